// SPDX-License-Identifier: GPL-3.0-or-later
// The "fem_reference" section of an experiment document.
#include <string>

#include "fiberfluid/experiment/read/json_fields.hpp"
#include "fiberfluid/experiment/read/readers.hpp"
#include "fiberfluid/fem/hyperelastic.hpp"

namespace fiberfluid::experiment {

FemReferenceSpec read_fem_reference(Fields& f) {
  FemReferenceSpec spec;
  spec.young = f.positive("E", 1.0);
  spec.poisson = f.number("nu");
  if (!(spec.poisson > -1.0 && spec.poisson < 0.5))
    f.fail("nu", "expected a Poisson ratio between -1 and 0.5 (exclusive)");
  const std::string material =
      f.choice("material", "linear", {"linear", "neo_hookean", "neo_hookean_incompressible"});
  spec.nonlinear = material != "linear";
  if (spec.nonlinear) spec.hyperelastic = fem::hyperelastic_from_string(material);
  spec.order = f.integer("order", spec.nonlinear ? 2 : 1, 1, 2);
  spec.mesh.size = f.non_negative("size", 0.0);
  spec.mesh.facet_distance = f.non_negative("facet_distance", 0.0);
  spec.mesh.feature_angle = f.positive("feature_angle", spec.mesh.feature_angle);
  if (spec.mesh.feature_angle > 180.0) f.fail("feature_angle", "expected degrees up to 180");
  f.finish();
  return spec;
}

}  // namespace fiberfluid::experiment
