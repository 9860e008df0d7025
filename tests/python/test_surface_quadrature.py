# SPDX-License-Identifier: GPL-3.0-or-later
"""experiments/surface_quadrature_check.py: the central fibers' one-point quadrature is second
order on a sphere away from supports (docs/model.md, issue 44's sphere study)."""
from experiment_scripts import load


def test_the_force_density_at_the_pole_converges_at_second_order():
    check = load("surface_quadrature_check")
    values = {kind: [value for _, value in check.pole_densities(5, 1.2, kind)]
              for kind in ("barycentric", "area-vector")}
    for kind, series in values.items():
        differences = [a - b for a, b in zip(series, series[1:])]
        ratios = [a / b for a, b in zip(differences, differences[1:])]
        assert all(ratio > 3.5 for ratio in ratios), (kind, series, ratios)
    # The two vertex areas converge to the same density (docs/model.md: -0.06976 at 16,386).
    assert abs(values["barycentric"][-1] - values["area-vector"][-1]) < 2e-5
    assert abs(values["barycentric"][-1] + 0.06984) < 1e-5
    # ... and the sums converge to the integral they stand for, not to another value.
    integral = check.continuum_pole_density(1.2)
    assert abs(integral + 0.069737) < 1e-6
    assert abs(values["area-vector"][-1] - integral) < 1.5e-4
