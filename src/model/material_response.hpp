// SPDX-License-Identifier: GPL-3.0-or-later
// The material-level response of central fibers with a law Y(e): an affine
// network of fibers in every direction (the microsphere view of a network:
// Bazant and Oh, ZAMM 66 (1986) 37; Miehe, Goektepe and Lulei, JMPS 52
// (2004) 2617) held incompressible by the fluid, with no body. Its strain
// energy per volume is
//
//   W(F) = 5 < psi(|F d|) >    over unit directions d,
//   psi(l) = integral from 1 to l of T0 + Y(e) e dl',  e = l' - 1,
//
// the fiber's stress being T0 + Y(e) e, as a central fiber's force is
// a (T0 L + Y(e) (l - L)) (T0 the law's rest tension, FiberLaw::rest_tension). The factor 5 makes a constant law Y a material of small-strain
// Young's modulus Y (shear modulus Y/3): for a volume-preserving strain
// eps the affine average <(d . eps d)^2> is 2 eps:eps / 15. This is the
// curve a body of fibers should follow in a homogeneous test (issue 57's
// patch test), and the one a fiber law is fitted to at material level.
#pragma once

#include <Eigen/Core>

#include "fiberfluid/material/hyperelastic_law.hpp"
#include "fiberfluid/model/fiber_law.hpp"

namespace fiberfluid::model {

// l_i dW/dl_i at principal stretches l (l1 l2 l3 = 1): the principal Cauchy
// stress but for the pressure.
Eigen::Vector3d fiber_network_stretch_work(const FiberLaw& law, const Eigen::Vector3d& l);
// The nominal stress along axis 1 in a homogeneous test at stretch l (Pa).
double fiber_network_nominal_stress(const FiberLaw& law, material::HomogeneousTest test, double l);

}  // namespace fiberfluid::model
