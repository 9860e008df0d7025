# SPDX-License-Identifier: GPL-3.0-or-later
"""The Python module: meshes, experiments from files and dicts, sweeps, numpy results."""
import json
import os

import numpy as np
import pytest

import fiberfluid

SOURCE = os.environ.get("FIBERFLUID_SOURCE_DIR",
                        os.path.join(os.path.dirname(__file__), "..", ".."))
MESHES = os.path.join(SOURCE, "data", "meshes")
EXPERIMENTS = os.path.join(SOURCE, "experiments")


def rectangle_dict():
    """The paper's worked example (model.md section 8), exact by elimination."""
    with open(os.path.join(EXPERIMENTS, "rectangle.json")) as f:
        document = json.load(f)
    document["stepping"]["boundary_method"] = "elimination"
    document["expected"] = []
    return document


def test_read_mesh_reports_counts_and_problems(tmp_path):
    liver = fiberfluid.read_mesh(os.path.join(MESHES, "liver.obj"))
    assert liver["vertices"].shape == (181, 3)
    assert liver["faces"].shape == (274, 3)
    assert liver["ok"]
    assert any("referenced by no face" in w for w in liver["warnings"])
    open_mesh = tmp_path / "open.obj"
    open_mesh.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\n")
    report = fiberfluid.read_mesh(str(open_mesh))
    assert not report["ok"]
    assert "not closed" in report["problems"][0]
    with pytest.raises(ValueError, match="cannot open"):
        fiberfluid.read_mesh(str(tmp_path / "missing.obj"))


def test_paper_rectangle_from_a_dict():
    result = fiberfluid.Experiment.from_dict(rectangle_dict()).run()
    assert result["success"]
    run = result["runs"][0]
    # u1x = u2x = -4, u1y = u4y = 16/3, P = 32 (the paper's solution)
    np.testing.assert_allclose(run["displacements"][:, 0], [-4, -4, 0, 0], atol=1e-10)
    np.testing.assert_allclose(run["displacements"][:, 1], [16 / 3, 0, 0, 16 / 3], atol=1e-10)
    assert run["pressure"] == pytest.approx(32.0, abs=1e-10)
    # The two supports carry the applied 2 x 1680 N.
    reactions = sum(r[-1] for r in run["steps"]["reactions"].values())
    np.testing.assert_allclose(reactions, [0.0, -3360.0], atol=1e-9)
    np.testing.assert_allclose(run["steps"]["applied_force"][-1], [0.0, 3360.0], atol=1e-9)


def test_a_sweep_gives_one_run_per_variant_with_step_arrays():
    experiment = fiberfluid.Experiment.from_file(os.path.join(EXPERIMENTS, "liver_sweep.json"))
    assert experiment.variants == ["Y10kPa", "Y20kPa", "Y40kPa", "Y80kPa"]
    result = experiment.run(jobs=2)
    assert result["success"]
    largest = [run["figures"]["max_displacement"] for run in result["runs"]]
    assert largest == sorted(largest, reverse=True)  # stiffer, smaller
    assert largest[1] == pytest.approx(0.0112338, abs=1e-7)  # liver_gravity.json
    steps = result["runs"][0]["steps"]
    assert steps["step"].tolist() == list(range(1, 11))
    assert steps["reactions"]["top"].shape == (10, 3)
    # Equilibrium at every step.
    total = steps["reactions"]["top"] + steps["applied_force"]
    assert np.abs(total).max() < 1e-10 * np.abs(steps["applied_force"]).max()


def test_bad_input_raises_value_error_naming_the_field():
    document = rectangle_dict()
    document["material"]["Y"] = "stiff"
    with pytest.raises(ValueError, match=r"<dict>: material.Y: expected a number"):
        fiberfluid.Experiment.from_dict(document)
    with pytest.raises(ValueError, match="cannot open the experiment file"):
        fiberfluid.Experiment.from_file("no_such_experiment.json")


def test_a_runaway_is_reported_not_returned(tmp_path):
    with open(os.path.join(EXPERIMENTS, "sphere.json")) as f:
        document = json.load(f)
    document["loads"][0]["density"] = 1e12
    result = fiberfluid.Experiment.from_dict(document).run(output=str(tmp_path / "out"))
    assert not result["success"]
    assert "step 1: runaway" in result["runs"][0]["message"]
    assert "positions" not in result["runs"][0]
    assert (tmp_path / "out.failed" / "FAILED").exists()


def test_writes_a_result_folder_like_the_command_line(tmp_path):
    out = tmp_path / "rect"
    fiberfluid.Experiment.from_dict(rectangle_dict()).run(output=str(out))
    summary = fiberfluid.summary(str(out))
    assert summary["units"]["force"] == "N"
    assert summary["runs"][0]["final"]["final_pressure"] == pytest.approx(32.0)
    for name in ("steps.csv", "vertices.csv", "final.obj", "series.pvd"):
        assert (out / name).exists(), name


def test_the_python_example_runs(tmp_path):
    import subprocess
    import sys
    png = tmp_path / "sweep.png"
    done = subprocess.run([sys.executable, os.path.join(EXPERIMENTS, "python_sweep.py"), str(png)],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    rows = [line.split() for line in done.stdout.splitlines()[1:7]]
    largest = [float(row[1]) for row in rows]
    assert largest == sorted(largest, reverse=True)
    assert png.stat().st_size > 10000


def test_a_program_gives_its_own_surface():
    """The paper's rectangle as numpy arrays instead of the dict's "surface"."""
    document = rectangle_dict()
    from_file = fiberfluid.Experiment.from_dict(document).run()
    del document["surface"]
    vertices = np.array([[15.0, 20.0], [15.0, -20.0], [-15.0, -20.0], [-15.0, 20.0]])
    segments = np.array([[1, 0], [2, 1], [3, 2], [0, 3]])  # counter-clockwise: outward normals
    with pytest.raises(ValueError, match="the given surface: inverted"):
        fiberfluid.Experiment.from_dict(document, vertices=vertices, faces=segments[:, ::-1])
    given = fiberfluid.Experiment.from_dict(document, vertices=vertices, faces=segments)
    assert given.num_vertices == 4
    result = given.run()
    assert result["success"]
    assert result["runs"][0]["pressure"] == pytest.approx(32.0, abs=1e-10)
    np.testing.assert_allclose(result["runs"][0]["displacements"],
                               from_file["runs"][0]["displacements"], atol=1e-12)
    with pytest.raises(ValueError, match="give both vertices and faces"):
        fiberfluid.Experiment.from_dict(document, vertices=vertices)
    with pytest.raises(ValueError, match="surface: missing"):
        fiberfluid.Experiment.from_dict(document)


def test_a_force_curve_fit_without_json():
    """The liver between paddles: its scan alone cannot tell Y0 from gamma; with the force, it can."""
    with open(os.path.join(EXPERIMENTS, "fit_paddles_liver_force.json")) as f:
        document = json.load(f)
    del document["fit"], document["expected"]
    document["surface"]["file"] = os.path.join(EXPERIMENTS, document["surface"]["file"])
    scan = fiberfluid.read_mesh(os.path.join(SOURCE, "data", "targets", "liver_paddles_step10_scan.obj"))
    rows = np.loadtxt(os.path.join(SOURCE, "data", "targets", "liver_paddles_force.csv"),
                      delimiter=",", skiprows=2)
    start = fiberfluid.Experiment.from_dict(document)
    parameters = [{"name": "Y0"}, {"name": "beta", "lower": -10, "upper": 20}, {"name": "gamma"}]
    surface = {"vertices": scan["vertices"], "faces": scan["faces"], "step": 10}
    alone = fiberfluid.fit(start, targets=[surface], parameters=parameters)
    assert alone["status"] == "not_identifiable"
    assert '"Y0", "gamma"' in alone["status_detail"]
    force = {"force": rows[:, 2], "travel": rows[:, 1] * 1e-3, "paddle": "upper"}
    both = fiberfluid.fit(start, targets=[surface, force], parameters=parameters)
    assert both["status"] == "converged", both["status_detail"]
    for name, truth in (("Y0", 20000.0), ("beta", 3.0), ("gamma", 200.0)):
        low, high = both["interval_95"][name]
        assert low <= truth <= high, name
    assert 0.05 < both["force_misfits"][0]["rms"] < 0.15
    with pytest.raises(ValueError, match="no paddle is labelled \"top\""):
        fiberfluid.fit(start, targets=[dict(force, paddle="top")], parameters=parameters)


def test_a_fit_without_json():
    """The paper's sphere: its deformed surface as numpy arrays, Y and gamma from a factor 3 away."""
    with open(os.path.join(EXPERIMENTS, "sphere.json")) as f:
        document = json.load(f)
    document["expected"] = []
    truth = fiberfluid.Experiment.from_dict(document).run()["runs"][0]
    mesh = fiberfluid.read_mesh(os.path.join(SOURCE, "data", "targets", "sphere_final.obj"))
    np.testing.assert_allclose(mesh["vertices"], truth["positions"], atol=1e-12)
    document["material"] = {"Y": 1000, "gamma": 9000}
    start = fiberfluid.Experiment.from_dict(document)
    result = fiberfluid.fit(start, targets=[{"vertices": truth["positions"], "faces": mesh["faces"]}],
                            parameters=[{"name": "Y"}, {"name": "gamma"}])
    assert result["success"], result["message"]
    assert not result["analytic_jacobian"]  # the paper's incremental scheme
    assert result["values"]["Y"] == pytest.approx(3000.0, rel=1e-6)
    assert result["values"]["gamma"] == pytest.approx(3000.0, rel=1e-6)
    assert result["distance"]["largest"] < 1e-8
    assert result["status"] == "converged"
    with pytest.raises(ValueError, match="not a parameter"):
        fiberfluid.fit(start, targets=[{"vertices": truth["positions"]}], parameters=[{"name": "E"}])
    # The options go through the same check as a file's (issue 30): no success at the start value.
    with pytest.raises(ValueError, match="loss_scale: expected a positive finite length"):
        fiberfluid.fit(start, targets=[{"vertices": truth["positions"]}], parameters=[{"name": "Y"}],
                       loss="huber", loss_scale=0)
    with pytest.raises(ValueError, match="method: expected levenberg-marquardt"):
        fiberfluid.fit(start, targets=[{"vertices": truth["positions"]}], parameters=[{"name": "Y"}],
                       method="newton")
    with pytest.raises(ValueError, match="expected a lower bound below the upper one"):
        fiberfluid.fit(start, targets=[{"vertices": truth["positions"]}],
                       parameters=[{"name": "Y", "lower": 1000, "upper": 1000}])
    # A scan in mm, scaled by its target's "scale".
    scaled = fiberfluid.fit(start, targets=[{"vertices": 1000 * truth["positions"], "faces": mesh["faces"],
                                             "scale": 1e-3}],
                            parameters=[{"name": "Y"}, {"name": "gamma"}])
    assert scaled["values"]["Y"] == pytest.approx(3000.0, rel=1e-6)


def test_a_name_never_makes_a_path_outside_the_output_root(tmp_path):
    with open(os.path.join(EXPERIMENTS, "rectangle.json")) as f:
        document = json.load(f)
    document["name"] = "../victim"
    with pytest.raises(ValueError, match="name: expected a name of letters, digits"):
        fiberfluid.Experiment.from_dict(document)
    # A folder another tool wrote is never replaced, and the run never starts.
    data = tmp_path / "data"
    data.mkdir()
    (data / "summary.json").write_text("{}")
    document["name"] = "rectangle"
    with pytest.raises(ValueError, match="was not written by fiberfluid"):
        fiberfluid.Experiment.from_dict(document).run(output=str(data))
    assert (data / "summary.json").read_text() == "{}"


def test_an_interactive_press_follows_the_schedule_and_returns():
    """The liver between paddles, pressed one step at a time by hand: on the experiment's
    own schedule it gives the batch run's paddle force; pressed back it comes to rest."""
    ex = fiberfluid.Experiment.from_file(os.path.join(EXPERIMENTS, "liver_paddles.json"))
    live = fiberfluid.Interactive(ex, "constant")
    start = live.point["paddles"]
    assert live.steps_taken == 0
    for k in range(1, 11):
        result = live.step(paddles=live.scheduled(k)["paddles"])
        assert result["success"], result["message"]
        assert result["newton_iterations"] <= 10
    # experiments/liver_paddles.json's expected figure (the batch Newton run)
    assert result["paddle_forces"]["upper"][1] == pytest.approx(-74.9966155, rel=1e-6)
    assert result["contacts"]["upper"] > 0
    assert live.positions.shape == ex.run()["runs"][0]["reference_positions"].shape
    used = np.unique(live.faces)  # liver.obj lists 42 vertices no face uses
    assert np.max(live.positions[used, 1]) <= live.point["paddles"]["upper"] + 1e-12
    # Back up by the dict of one paddle, in two moves: the liver rests again.
    middle = (start["upper"] + live.point["paddles"]["upper"]) / 2
    assert live.step(paddles={"upper": middle})["success"]
    back = live.step(paddles={"upper": start["upper"]})
    assert back["success"], back["message"]
    assert np.linalg.norm(back["paddle_forces"]["upper"]) < 1e-6
    reference = ex.run()["runs"][0]["reference_positions"]
    assert np.max(np.abs(live.positions - reference)) < 1e-9
    with pytest.raises(ValueError, match="no paddles labelled \"side\""):
        live.step(paddles={"side": 0.0})
    with pytest.raises(ValueError, match="paddles: 1 values given, the experiment has 2"):
        live.step(paddles=[0.0])
    with pytest.raises(ValueError, match="no variant named"):
        fiberfluid.Interactive(ex, "nonsense")


def test_a_file_fit_runs_the_commands_workflow(tmp_path):
    """fit_file is `fiberfluid fit`: the same workflow, folder, fit.json and ending."""
    out = fiberfluid.fit_file(os.path.join(EXPERIMENTS, "fit_synthetic_liver.json"),
                              str(tmp_path / "fit"))
    assert out["status"] == "converged" and out["success"] and out["exit_status"] == 0
    assert out["folder"] == tmp_path / "fit"  # a pathlib.Path
    values = {p["name"]: p["value"] for p in out["report"]["parameters"]}
    # The values `fiberfluid fit experiments/fit_synthetic_liver.json` prints (truth 20 kPa, 3, 200).
    assert values["Y0"] == pytest.approx(20593.99672, rel=1e-8)
    assert values["beta"] == pytest.approx(3.034525393, rel=1e-8)
    assert values["gamma"] == pytest.approx(199.3945108, rel=1e-8)
    for name in ("fit_iterations.csv", "fit_distances.csv", "summary.json", "steps.csv"):
        assert (tmp_path / "fit" / name).exists(), name
    # A fit the scan cannot separate ends not_identifiable in DIR.failed, exit 2, as the command.
    shape = fiberfluid.fit_file(os.path.join(EXPERIMENTS, "fit_paddles_liver_shape.json"),
                                str(tmp_path / "shape"))
    assert shape["status"] == "not_identifiable" and not shape["success"]
    assert shape["exit_status"] == 2 and shape["folder"] == tmp_path / "shape.failed"
    assert "not_identifiable" in shape["failure"]
    with pytest.raises(ValueError, match='no "fit" section'):
        fiberfluid.fit_file(os.path.join(EXPERIMENTS, "sphere.json"), str(tmp_path / "sphere"))
