// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// A fit set up from an experiment's "fit" section (or a calibration over
// specimens), its figures, and the experiment at the fitted values. What a
// fit writes is write/fit_files.hpp.

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "fiberfluid/experiment/experiment.hpp"
#include "fiberfluid/experiment/run/runner.hpp"
#include "fiberfluid/fit/calibration.hpp"
#include "fiberfluid/fit/joint_calibration.hpp"
#include "fiberfluid/fit/multistart.hpp"

namespace fiberfluid::experiment {

// A fit set up from an experiment's "fit" section: the targets read, the
// calibration built on the experiment's (single) case.
struct FitSetup {
  std::vector<fit::MeasuredStep> targets;
  std::vector<fit::ForceCurve> force_curves;
  std::unique_ptr<fit::Calibration> calibration;
};
// Throws InputError naming the file and field. `progress` is called after
// each iteration of the fit.
FitSetup setup_fit(const Experiment& experiment,
                   std::function<void(const fit::IterationRecord&)> progress = {});

// The parameters' values in the fit.json of an earlier fit (fit.start_from).
std::map<std::string, double> fitted_values(const std::filesystem::path& fit_json_file);

// The command line's exit status for a fit that ended so: 0 converged, 4
// converged with parameters on their bounds, 130 interrupted, 2 otherwise.
int fit_exit_status(fit::FitStatus status);
// Whether the output folder takes a fit that ended so (else DIR.failed).
bool fit_result_kept(fit::FitStatus status);

// The fit's headline figures, "fit.NAME" for each parameter and the
// distance statistics (fit.distance_sd_share is the method paper's figure).
std::map<std::string, double> fit_figures(const fit::FitResult& result);

// A multi-start search's figures: fit.optima (distinct optima found),
// fit.best_optimum_starts (how many starts reached the best one).
std::map<std::string, double> multistart_figures(const fit::MultistartResult& search);

// fit.mesh_check: the same fit on the surface one step coarser or finer
// (mesh_study.hpp's refinement: 1.5 for segments and remesh_vertices, 2 for
// subdivisions), from the fitted values (`at_fit`: with_fitted_material's).
// Its parameters' shifts from the fit are the mesh's share of their
// uncertainty: what the data pin is one mesh's model, and this says how far
// the material moves with the mesh.
struct MeshCheck {
  std::string resolution;  // the other mesh's, e.g. "segments [12, 11]"
  fit::FitResult fitted;   // on it (its status says whether it converged)
  std::string failure;     // why the check could not fit at all ("": `fitted` holds)
};

// The experiment's fit on the other mesh, built, every vertex index it
// names mapped to the same point there (mesh_study.hpp). Throws InputError
// naming fit.mesh_check when it cannot be: no resolution to change, a point
// the other mesh lacks, a mesh its fibers refuse. A fit checks this before
// it starts, so that a check that cannot run costs no fit.
Experiment mesh_check_experiment(const Experiment& experiment, std::string* resolution);

// The check's fit from the fitted values. A failure on the other mesh (a
// run that fails there) is the check's `failure`, never the fit's loss;
// Ctrl-C throws Interrupted.
MeshCheck run_mesh_check(const Experiment& at_fit);

// The mesh check's figures: fit.mesh_check.NAME (the value on the other mesh)
// and fit.mesh_shift.NAME (that less the fit's).
std::map<std::string, double> mesh_check_figures(const fit::FitResult& fitted,
                                                 const MeshCheck& check);

// The experiment with the fitted material (to run and write as usual).

Experiment with_fitted_material(const Experiment& experiment, const fit::Calibration& calibration,
                                const fit::FitResult& result);

// The values of `m` written into an experiment's "material" section in the
// form the section already has: a law's parameters and axis factors, or the
// linear model's Y (one, or one per axis), and gamma.
void write_material_values(const model::Material& m, int dim, nlohmann::json& material);

// A calibration over specimens ("kind": "calibration") set up: each
// specimen's fit (its targets read, its calibration) and the joint one over
// them. Throws InputError naming the specimen and field.
struct JointSetup {
  std::vector<FitSetup> specimens;
  std::unique_ptr<fit::JointCalibration> joint;
};
JointSetup setup_joint(const Experiment& experiment,
                       std::function<void(const fit::IterationRecord&)> progress = {});

// Its figures: fit.cost, fit.SHARED, fit.SPECIMEN.PARAMETER and each
// specimen's distance statistics (fit.SPECIMEN.distance_sd_share: the sd as
// a share of its body's length).
std::map<std::string, double> joint_figures(const Experiment& experiment,
                                            const fit::JointFitResult& result);

}  // namespace fiberfluid::experiment
