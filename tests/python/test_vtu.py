# SPDX-License-Identifier: GPL-3.0-or-later
"""The .vtu series read by an independent reader (meshio): ASCII and compressed files hold the
same grid and data, and the data says what README says it does."""
import json
import os

import numpy as np
import pytest

import fiberfluid

meshio = pytest.importorskip("meshio")  # scripts/install-deps.sh installs python3-meshio

SOURCE = os.environ.get("FIBERFLUID_SOURCE_DIR",
                        os.path.join(os.path.dirname(__file__), "..", ".."))


def sphere(vtk_format):
    with open(os.path.join(SOURCE, "experiments", "sphere.json")) as f:
        document = json.load(f)
    document["expected"] = []
    document["output"] = {"vtk_format": vtk_format, "every": 5}
    document["name"] = "sphere_" + vtk_format
    return document


def test_ascii_and_compressed_series_hold_the_same_data(tmp_path):
    grids = {}
    for vtk_format in ("ascii", "compressed"):
        out = tmp_path / vtk_format
        fiberfluid.Experiment.from_dict(sphere(vtk_format)).run(output=str(out))
        text = (out / "vtk" / "step_0010.vtu").read_bytes()
        assert (b'format="appended"' in text) == (vtk_format == "compressed")
        assert (b'<AppendedData encoding="raw">' in text) == (vtk_format == "compressed")
        grids[vtk_format] = meshio.read(str(out / "vtk" / "step_0010.vtu"))
    a, c = grids["ascii"], grids["compressed"]
    assert np.array_equal(a.points, c.points)  # 17 digits in ASCII: the same doubles
    assert np.array_equal(a.cells_dict["triangle"], c.cells_dict["triangle"])
    for name in ("displacement", "displacement_magnitude", "area_vector", "reference_position"):
        assert np.array_equal(a.point_data[name], c.point_data[name]), name
    assert np.array_equal(a.cell_data["area_change"][0], c.cell_data["area_change"][0])
    # Points are the deformed positions: the reference plus the displacement.
    assert np.allclose(c.point_data["reference_position"] + c.point_data["displacement"],
                       c.points, rtol=0, atol=1e-15)
    # Field data: the step, its load factors (gravity, the pull) and the pressure.
    assert c.field_data["step"][0] == 10
    assert np.allclose(c.field_data["load_factors"], [1.0, 1.0])
    summary = json.loads((tmp_path / "compressed" / "summary.json").read_text())
    assert c.field_data["pressure"][0] == pytest.approx(summary["figures"]["final_pressure"],
                                                        rel=1e-15)
    # The faces' area change is their area now over at rest.
    tri = c.cells_dict["triangle"]

    def areas(p):
        return 0.5 * np.linalg.norm(np.cross(p[tri[:, 1]] - p[tri[:, 0]],
                                             p[tri[:, 2]] - p[tri[:, 0]]), axis=1)
    ratio = areas(c.points) / areas(c.point_data["reference_position"])
    assert np.allclose(c.cell_data["area_change"][0], ratio, rtol=1e-12)
    # The compressed file is smaller.
    assert (tmp_path / "compressed" / "vtk" / "step_0010.vtu").stat().st_size < \
        0.7 * (tmp_path / "ascii" / "vtk" / "step_0010.vtu").stat().st_size


def test_reactions_and_contact_forces_sum_to_the_steps_forces(tmp_path):
    # The sphere's support: its vertices' reactions sum to the group's reaction in summary.json.
    out = tmp_path / "sphere"
    fiberfluid.Experiment.from_dict(sphere("ascii")).run(output=str(out))
    grid = meshio.read(str(out / "vtk" / "step_0010.vtu"))
    summary = json.loads((out / "summary.json").read_text())
    last = summary["runs"][0]["steps"][-1]
    (group, reaction), = last["reactions"].items()
    assert np.allclose(grid.point_data["support_reaction"].sum(axis=0), reaction, rtol=1e-12,
                       atol=1e-9)
    assert not grid.point_data["contact_force"].any()  # no paddle
    # The liver between paddles: each paddle's contact forces sum to its force.
    with open(os.path.join(SOURCE, "experiments", "liver_paddles.json")) as f:
        document = json.load(f)
    document["variants"] = document["variants"][:1]
    document["expected"] = []
    document["stepping"]["steps"] = 3
    document["surface"]["file"] = os.path.join(SOURCE, "experiments", document["surface"]["file"])
    out = tmp_path / "liver"
    fiberfluid.Experiment.from_dict(document).run(output=str(out))
    grid = meshio.read(str(out / "constant" / "vtk" / "step_0003.vtu"))
    summary = json.loads((out / "summary.json").read_text())
    figures = summary["figures"]
    contact = grid.point_data["contact_force"]
    assert contact[:, 1].sum() == pytest.approx(figures["constant.paddle_force.upper"] +
                                                figures["constant.paddle_force.lower"], rel=1e-12)
    pressed = contact[:, 1] < 0  # the upper paddle pushes down on the vertices it holds
    assert contact[pressed, 1].sum() == pytest.approx(figures["constant.paddle_force.upper"],
                                                      rel=1e-12)
    assert np.abs(grid.point_data["support_reaction"]).sum() > 0  # the resting vertices


def test_fibers_are_written_with_their_strain_and_force(tmp_path):
    # The sphere's 13,041 fibers (every pair kept: a convex body) at the reference and at the end.
    document = sphere("ascii")
    document["fibers"] = {"write": "kept"}
    out = tmp_path / "fibers"
    fiberfluid.Experiment.from_dict(document).run(output=str(out))
    rest = meshio.read(str(out / "fibers.vtu"))
    final = meshio.read(str(out / "fibers_final.vtu"))
    lines = rest.cells_dict["line"]
    assert len(lines) == 162 * 161 // 2
    assert np.array_equal(final.cells_dict["line"], lines)

    def lengths(grid):
        return np.linalg.norm(grid.points[lines[:, 0]] - grid.points[lines[:, 1]], axis=1)
    assert np.allclose(rest.cell_data["rest_length"][0], lengths(rest), rtol=1e-14)
    # The last state's points are the last step's, and each strain is r / L - 1.
    step = meshio.read(str(out / "vtk" / "step_0010.vtu"))
    assert np.array_equal(final.points, step.points)
    strain = final.cell_data["strain"][0]
    assert np.allclose(strain, lengths(final) / lengths(rest) - 1.0, rtol=0, atol=1e-13)
    # A vector spring's force is a Y (u_i - u_j): its tension along the fiber is at most its size.
    force, tension = final.cell_data["force"][0], final.cell_data["tension"][0]
    assert np.all(force >= np.abs(tension) * (1 - 1e-12))
    assert np.all(np.isfinite(force)) and force.max() > 0
    # Stretched fibers mostly pull (their ends' displacements differ mostly along them).
    stretched = strain > 1e-3
    assert np.mean(tension[stretched] > 0) > 0.9
    # Each face's surface-tension force: positive where the surface is strained.
    per_face = step.cell_data["surface_tension_force"][0]
    assert per_face.shape == (len(step.cells_dict["triangle"]),)
    assert np.all(np.isfinite(per_face)) and per_face.min() >= 0 and per_face.max() > 0
    first = meshio.read(str(out / "vtk" / "step_0000.vtu"))
    assert not first.cell_data["surface_tension_force"][0].any()  # nothing moved yet
