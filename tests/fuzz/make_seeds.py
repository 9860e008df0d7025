#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Writes the fuzz targets' small seed inputs into tests/fuzz/seeds/TARGET/.

(The seeds of bad input, such as experiment/unsafe_variant_name.json, were
written by hand from what was found from outside in issue 11.)

The repository's meshes (data/meshes) and experiments (experiments/) are
seeds too; scripts/fuzz.sh adds them. These cover what those do not: every
format variant (OFF, STL ASCII and binary, PLY ASCII and both binary byte
orders, OBJ index forms and 2D outlines) and small experiments of each kind.
"""
import json
import pathlib
import struct

HERE = pathlib.Path(__file__).resolve().parent / "seeds"

# A tetrahedron with outward faces, and a cube with outward quads.
TET_V = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)]
TET_F = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]
CUBE_V = [(x, y, z) for z in (0, 1) for y in (0, 1) for x in (0, 1)]
CUBE_F = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]


# An L-shaped prism: concave, so a model on it prunes fibers (in milliseconds).
L_XY = [(0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)]
L_V = [(x, y, 0) for x, y in L_XY] + [(x, y, 1) for x, y in L_XY]
L_CAP = [(3, 4, 5), (3, 5, 0), (3, 0, 1), (3, 1, 2)]  # a fan from the reflex corner, counter-clockwise
L_F = ([(a, c, b) for a, b, c in L_CAP] + [(a + 6, b + 6, c + 6) for a, b, c in L_CAP] +
       [(k, (k + 1) % 6, (k + 1) % 6 + 6, k + 6) for k in range(6)])


def write(target, name, data):
    folder = HERE / target
    folder.mkdir(parents=True, exist_ok=True)
    (folder / name).write_bytes(data if isinstance(data, bytes) else data.encode())


def obj(V, F, form="{}"):
    lines = [f"v {x} {y} {z}" for x, y, z in V]
    lines += ["f " + " ".join(form.format(i + 1) for i in f) for f in F]
    return "\n".join(lines) + "\n"


def off(V, F):
    lines = ["OFF", f"{len(V)} {len(F)} 0"] + [f"{x} {y} {z}" for x, y, z in V]
    lines += [f"{len(f)} " + " ".join(map(str, f)) for f in F]
    return "\n".join(lines) + "\n"


def triangles(V, F):
    for f in F:
        for k in range(1, len(f) - 1):
            yield V[f[0]], V[f[k]], V[f[k + 1]]


def stl_ascii(V, F):
    out = ["solid seed"]
    for a, b, c in triangles(V, F):
        out += ["facet normal 0 0 0", "outer loop"]
        out += [f"vertex {p[0]} {p[1]} {p[2]}" for p in (a, b, c)]
        out += ["endloop", "endfacet"]
    return "\n".join(out + ["endsolid seed"]) + "\n"


def stl_binary(V, F):
    tris = list(triangles(V, F))
    data = b"binary seed".ljust(80, b" ") + struct.pack("<I", len(tris))
    for t in tris:
        data += struct.pack("<3f", 0, 0, 0)
        for p in t:
            data += struct.pack("<3f", *p)
        data += b"\0\0"
    return data


def ply(V, F, fmt):
    header = (f"ply\nformat {fmt} 1.0\ncomment seed\nelement vertex {len(V)}\n"
              "property float x\nproperty float y\nproperty float z\n"
              f"element face {len(F)}\nproperty list uchar int vertex_indices\nend_header\n")
    if fmt == "ascii":
        body = "".join(f"{x} {y} {z}\n" for x, y, z in V)
        body += "".join(f"{len(f)} " + " ".join(map(str, f)) + "\n" for f in F)
        return (header + body).encode()
    e = "<" if fmt == "binary_little_endian" else ">"
    body = b"".join(struct.pack(e + "3f", *v) for v in V)
    body += b"".join(struct.pack(e + "B" + "i" * len(f), len(f), *f) for f in F)
    return header.encode() + body


def main():
    write("obj", "tetrahedron.obj", obj(TET_V, TET_F))
    write("obj", "cube_quads_texture_normal.obj", obj(CUBE_V, CUBE_F, "{0}/{0}/{0}"))
    write("obj", "tetrahedron_negative.obj",
          obj(TET_V, []) + "".join(f"f {a - 4} {b - 4} {c - 4}\n" for a, b, c in TET_F))
    write("obj", "l_prism_concave.obj", obj(L_V, L_F))
    write("obj", "square_2d.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nl 1 2\nl 2 3\nl 3 4\nl 4 1\n")
    write("off", "tetrahedron.off", off(TET_V, TET_F))
    write("off", "cube_quads.off", off(CUBE_V, CUBE_F))
    write("stl_ascii", "tetrahedron.stl", stl_ascii(TET_V, TET_F))
    write("stl_ascii", "cube.stl", stl_ascii(CUBE_V, CUBE_F))
    write("stl_binary", "tetrahedron.stl", stl_binary(TET_V, TET_F))
    write("stl_binary", "cube.stl", stl_binary(CUBE_V, CUBE_F))
    write("ply_ascii", "tetrahedron.ply", ply(TET_V, TET_F, "ascii"))
    write("ply_ascii", "cube_quads.ply", ply(CUBE_V, CUBE_F, "ascii"))
    for order in ("binary_little_endian", "binary_big_endian"):
        write("ply_binary", f"tetrahedron_{order}.ply", ply(TET_V, TET_F, order))
        write("ply_binary", f"cube_{order}.ply", ply(CUBE_V, CUBE_F, order))

    sphere = {"generator": "icosphere", "subdivisions": 1, "radius": 0.05}
    experiments = {
        "sphere_gravity": {"surface": sphere, "material": {"Y": 5000, "gamma": 1},
                           "supports": [{"where": "z <= -0.04"}],
                           "loads": [{"type": "gravity", "acceleration": [0, 0, -9.81],
                                      "density": 1000}],
                           "stepping": {"steps": 3}},
        "cube_newton_paddles": {
            "surface": {"generator": "box", "min": [0, 0, 0], "max": [1, 1, 1],
                        "segments": [2, 2, 2]},
            "material": {"law": {"type": "exponential", "Y0": 1000, "beta": 2}, "gamma": 5},
            "paddles": [{"label": "top", "axis": "z", "side": "above", "compression": 0.2},
                        {"label": "bottom", "axis": "z", "side": "below", "travel": 0}],
            "supports": [{"where": "z <= 0.01", "axes": "xy"}],
            "stepping": {"steps": 2, "scheme": "newton"}},
        "rectangle_sweep": {
            "surface": {"generator": "rectangle", "min": [0, 0], "max": [2, 1],
                        "segments": [4, 2]},
            "material": {"Y": 100, "gamma": 0.5},
            "supports": [{"box": {"min": [-0.1, -0.1], "max": [0.1, 1.1]}}],
            "prescribed": [{"where": "x >= 1.9", "displacement": [0.1, 0]}],
            "stepping": {"steps": 2, "solver": "pcg"},
            "variants": [{"name": "soft"}, {"name": "stiff", "material": {"Y": 1000}}]},
        "l_prism_pruned": {
            "surface": {"file": "../tests/fuzz/seeds/obj/l_prism_concave.obj", "scale": 0.1},
            "material": {"Y": 1000, "gamma": 1}, "fibers": {"write": "pruned"},
            "supports": [{"where": "z <= 0.01"}],
            "loads": [{"type": "gravity", "acceleration": [0, 0, -9.81]}],
            "stepping": {"steps": 2, "scheme": "newton"}},
        "concave_polygon_2d": {
            "surface": {"generator": "polygon",
                        "points": [[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]]},
            "material": {"Y": 100}, "supports": [{"where": "y <= 0.1"}],
            "loads": [{"type": "point", "vertex": 4, "force": [0.5, 0]}]},
        "liver_point_load": {
            "surface": {"file": "../data/meshes/liver.obj", "scale": 0.04},
            "material": {"Y": 20000, "gamma": 50},
            "supports": [{"where": "y <= 0.015"}],
            "loads": [{"type": "point", "vertex": 10, "force": [0, -1, 0]}],
            "stepping": {"steps": 2, "solver": "cholmod"}},
    }
    for name, document in experiments.items():
        text = json.dumps(dict(name=name, **document), indent=1)
        write("experiment", name + ".json", text)
        write("model_setup", name + ".json", text)
    fit_and_compare_seeds()


def fit_sphere(**fit_changes):
    """experiments/fit_sphere.json, small, with changes to its fit section."""
    document = {
        "surface": {"generator": "icosphere", "subdivisions": 1, "radius": 1.0},
        "material": {"Y": 1000, "gamma": 9000},
        "supports": [{"where": "z >= 0.8", "axes": "xyz", "label": "cap"}],
        "loads": [{"type": "gravity", "acceleration": [0, 0, -10], "density": 1000}],
        "stepping": {"steps": 3},
        "fit": {"targets": [{"file": "../data/targets/sphere_final.obj"}],
                "parameters": [{"name": "Y", "lower": 10, "upper": 1e6},
                               {"name": "gamma", "lower": 10, "upper": 1e6}],
                "objective": {"exclude": {"where": "z >= 0.8"}}}}
    document["fit"].update(fit_changes)
    return document


def fit_and_compare_seeds():
    """Issues 27 and 30: each reproducer found from outside is a seed."""
    fits = {
        "plain": fit_sphere(),
        "difference_step_5": fit_sphere(jacobian="finite-differences", difference_step=5),
        "difference_step_tiny": fit_sphere(jacobian="finite-differences", difference_step=1e-300),
        "equal_bounds": fit_sphere(parameters=[{"name": "Y", "lower": 1000, "upper": 1000}]),
        "loss_scale_zero": fit_sphere(objective={"loss": "huber", "loss_scale": 0}),
        "scan_in_mm": fit_sphere(targets=[{"file": "../data/targets/sphere_final.obj", "units": "mm"}]),
        "alignment_scale": fit_sphere(parameters=[{"name": "scale", "lower": 0.5, "upper": 2},
                                                  {"name": "translation_z"}]),
        "start_from_missing": fit_sphere(start_from="no_such_fit.json"),
    }
    for name, document in fits.items():
        write("fit_section", name + ".json", json.dumps(dict(name=name, **document), indent=1))
    escaping = fit_sphere()
    escaping["name"] = "../victim"
    write("fit_section", "name_escapes.json", json.dumps(escaping))
    write("experiment", "name_escapes.json", json.dumps(escaping))
    long_variant = dict(fit_sphere(), name="long", variants=[{"name": "v" * 300}])
    del long_variant["fit"]
    write("experiment", "variant_name_300.json", json.dumps(long_variant))
    nested = '{"name": "deep", "stepping": {"steps": ' + "[" * 30000 + "]" * 30000 + "}}"
    write("experiment", "nested_30000.json", nested)
    write("fit_section", "nested_30000.json", nested)

    # compare: polygons (2D) and solids (3D) against a unit square or cube.
    write("compare_2d", "square_far.obj", obj([(x + 1e8, y + 1e8, 0) for x, y in [(0, 0), (1, 0), (1, 1), (0, 1)]], [])
          + "l 1 2\nl 2 3\nl 3 4\nl 4 1\n")
    write("compare_2d", "huge_coordinate.obj", "v 0 0 0\nv 1e301 0 0\nv 0 1 0\nl 1 2\nl 2 3\nl 3 1\n")
    write("compare_2d", "l_shape.obj", obj([(x, y, 0) for x, y in L_XY], [])
          + "".join(f"l {k + 1} {(k + 1) % 6 + 1}\n" for k in range(6)))
    write("compare_3d", "cube_far.obj", obj([(x + 1e8, y + 1e8, z + 1e8) for x, y, z in CUBE_V], CUBE_F))
    write("compare_3d", "cube_moved.obj", obj([(x + 0.5, y + 0.5, z + 0.5) for x, y, z in CUBE_V], CUBE_F))
    write("compare_3d", "open_soup.obj", obj(TET_V, TET_F[:3]))
    write("compare_3d", "point_cloud.obj", "v 0.5 0.5 1\nv 0.5 0.5 0\nv 0.2 0.5 0.8\n")
    write("compare_3d", "huge_coordinate.obj", obj([(x * 1e301, y, z) for x, y, z in TET_V], TET_F))


if __name__ == "__main__":
    main()
