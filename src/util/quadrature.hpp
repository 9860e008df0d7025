// SPDX-License-Identifier: GPL-3.0-or-later
// Quadrature rules shared by the finite elements and the material-level
// responses.
#pragma once

#include <vector>

namespace fiberfluid {

// Gauss-Legendre points and weights on [0, 1] (exact for polynomials of
// degree 2n - 1; the weights sum to 1).
void gauss_legendre_unit(int n, std::vector<double>* x, std::vector<double>* w);

}  // namespace fiberfluid
