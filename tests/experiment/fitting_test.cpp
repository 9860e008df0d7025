// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/experiment/run/fit_setup.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <functional>
#include <map>

#include "fiberfluid/experiment/read/schema.hpp"
#include "fiberfluid/experiment/write/fit_files.hpp"
#include "fiberfluid/experiment/write/outputs.hpp"
#include "fiberfluid/geom/mesh_io.hpp"
#include "fiberfluid/util/error.hpp"
#include "test_support.hpp"

namespace fiberfluid::experiment {
namespace {

// The fit experiments as `fiberfluid fit` runs them: calibrate, run at the
// fitted values, check the expected figures.
class FitExperiment : public ::testing::TestWithParam<const char*> {};

TEST_P(FitExperiment, RecoversItsParametersAndMeetsItsExpectedFigures) {
  const Experiment ex = load_experiment(testing::experiment_file(GetParam()));
  const FitSetup setup = setup_fit(ex);
  const fit::FitResult fitted = setup.calibration->run();
  ASSERT_TRUE(fitted.success) << fitted.message;
  const Experiment at_fit = with_fitted_material(ex, *setup.calibration, fitted);
  ExperimentResult result = run_experiment(at_fit);
  ASSERT_TRUE(result.runs_succeeded());
  for (const auto& [name, value] : fit_figures(fitted)) result.figures[name] = value;
  result.checks = check_expected(at_fit, result);
  EXPECT_FALSE(result.checks.empty());
  for (const FigureCheck& c : result.checks) EXPECT_TRUE(c.passed) << c.Describe();

  testing::ScratchDir dir;
  write_fit_files(dir.path(), at_fit, setup, fitted, result);
  std::ifstream in(dir.path() / "fit.json");
  const nlohmann::json report = nlohmann::json::parse(in);
  EXPECT_EQ(report["parameters"].size(), fitted.names.size());
  EXPECT_TRUE(report["success"].get<bool>());
  EXPECT_EQ(report["targets"].size(), setup.targets.size());
  for (const char* file : {"fit_iterations.csv", "fit_distances.csv", "fit_target_0.vtu"})
    EXPECT_TRUE(std::filesystem::exists(dir.path() / file)) << file;
}

INSTANTIATE_TEST_SUITE_P(Experiments, FitExperiment,
                         ::testing::Values("fit_sphere.json", "fit_synthetic_liver_exact.json",
                                           "fit_liver_fem.json", "fit_cantilever_large.json",
                                           "fit_liver_force.json"));

// A compression test's scan and force curve (noisy, issue 24): the fit's 95%
// intervals hold the truth, both misfits are reported, and the curve's rows
// are written beside the distances. Without the curve (the scan alone) the
// same fit cannot tell Y0 from gamma.
TEST(ForceCurveFit, RecoversTheTruthWithinItsIntervalsAndTheScanAloneCannot) {
  const Experiment ex = load_experiment(testing::experiment_file("fit_paddles_liver_force.json"));
  const FitSetup setup = setup_fit(ex);
  ASSERT_EQ(setup.force_curves.size(), 1u);
  EXPECT_TRUE(setup.calibration->analytic_jacobian());
  const fit::FitResult fitted = setup.calibration->run();
  ASSERT_EQ(fitted.status, fit::FitStatus::Converged) << fitted.message << fitted.status_detail;
  const std::map<std::string, double> truth = {{"Y0", 20000.0}, {"beta", 3.0}, {"gamma", 200.0}};
  for (size_t k = 0; k < fitted.names.size(); ++k) {
    const auto i = static_cast<Eigen::Index>(k);
    EXPECT_LE(fitted.lower_95[i], truth.at(fitted.names[k])) << fitted.names[k];
    EXPECT_GE(fitted.upper_95[i], truth.at(fitted.names[k])) << fitted.names[k];
    EXPECT_LT(fitted.upper_95[i] - fitted.lower_95[i], 0.3 * truth.at(fitted.names[k]))
        << fitted.names[k];  // and they are informative
  }
  ASSERT_EQ(fitted.force_misfits.size(), 1u);
  // The misfit is the curve's 0.1 N of noise.
  EXPECT_GT(fitted.force_misfits[0].rms, 0.05);
  EXPECT_LT(fitted.force_misfits[0].rms, 0.15);
  const Experiment at_fit = with_fitted_material(ex, *setup.calibration, fitted);
  ExperimentResult result = run_experiment(at_fit);
  for (const auto& [name, value] : fit_figures(fitted)) result.figures[name] = value;
  result.checks = check_expected(at_fit, result);
  EXPECT_FALSE(result.checks.empty());
  for (const FigureCheck& c : result.checks) EXPECT_TRUE(c.passed) << c.Describe();
  EXPECT_NEAR(result.figures.at("fit.force_rms"), fitted.force_misfits[0].rms, 1e-15);
  testing::ScratchDir dir;
  write_fit_files(dir.path(), at_fit, setup, fitted, result);
  std::ifstream in(dir.path() / "fit.json");
  const nlohmann::json report = nlohmann::json::parse(in);
  EXPECT_EQ(report["force_curves"][0]["paddle"], "upper");
  EXPECT_EQ(report["counts"]["force_rows"], 10);
  EXPECT_NEAR(report["force_curves"][0]["misfit"]["rms"].get<double>(), fitted.force_misfits[0].rms,
              1e-15);
  std::ifstream rows(dir.path() / "fit_force_0.csv");
  std::string header, first;
  std::getline(rows, header);
  std::getline(rows, first);
  EXPECT_EQ(header, "travel_m,measured_N,simulated_N,misfit_N");
  EXPECT_EQ(first.rfind("0.005927138,4.1991,", 0), 0u) << first;  // mm read as m
}

nlohmann::json sphere_fit_document() {
  std::ifstream in(testing::experiment_file("fit_sphere.json"));
  return nlohmann::json::parse(in);
}

void expect_fit_error(const nlohmann::json& document, const std::string& part) {
  try {
    const Experiment ex =
        parse_experiment(document, testing::experiment_file("").parent_path(), "doc");
    setup_fit(ex);
    ADD_FAILURE() << "no error, expected one mentioning '" << part << "'";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

// Issue 43, "every documented option is honoured": each option of the fit
// section, with each method, is either taken by that method or refused,
// naming the option and the method that would take it.
TEST(EveryDocumentedOptionIsHonoured, EachOptionWithEachMethodIsTakenOrRefused) {
  const std::vector<std::string> methods = {"levenberg-marquardt", "multistart", "bobyqa",
                                            "direct-l", "crs2"};
  struct Option {
    const char* key;
    nlohmann::json value;
    std::vector<std::string> taken_by;  // the others refuse it
  };
  const std::vector<std::string> all = methods;
  const std::vector<std::string> trust_region = {"levenberg-marquardt", "multistart"};
  const std::vector<Option> options = {
      {"max_iterations", 7, trust_region},
      {"max_evaluations", 9, all},
      {"function_tolerance", 1e-6, all},
      {"parameter_tolerance", 1e-6, all},
      {"initial_trust_region_radius", 10.0, trust_region},
      {"max_step_factor", 2.0, trust_region},
      {"difference_step", 1e-4, all},  // the Jacobian's, for every method's covariance
      {"starts", 3, {"multistart"}},
      {"same_optimum", 0.01, {"multistart"}}};
  for (const std::string& method : methods)
    for (const Option& option : options) {
      nlohmann::json d = sphere_fit_document();
      d["fit"]["method"] = method;
      d["fit"]["jacobian"] = "finite-differences";
      d["fit"][option.key] = option.value;
      const bool taken = std::find(option.taken_by.begin(), option.taken_by.end(), method) !=
                         option.taken_by.end();
      if (taken) {
        const Experiment ex =
            parse_experiment(d, testing::experiment_file("").parent_path(), "doc");
        const fit::FitOptions& o = ex.fit()->options;
        const std::string key = option.key;
        if (key == "max_iterations") {
          EXPECT_EQ(o.max_iterations, 7);
        }
        if (key == "max_evaluations") {
          EXPECT_EQ(o.max_evaluations, 9);
        }
        if (key == "initial_trust_region_radius") {
          EXPECT_EQ(o.initial_trust_region_radius, 10.0);
        }
        if (key == "max_step_factor") {
          EXPECT_EQ(o.max_step_factor, 2.0);
        }
        if (key == "difference_step") {
          EXPECT_EQ(o.difference_step, 1e-4);
        }
        if (key == "starts") {
          EXPECT_EQ(ex.fit()->multistart->starts, 3);
        }
      } else {
        expect_fit_error(d, std::string("fit.") + option.key + ": only with");
      }
    }

  // Taken means honoured. Levenberg-Marquardt stops at max_evaluations (it
  // ran 82 forward runs with a limit of 5 and said "converged"): a point that
  // would need more runs is not run, and the fit ends iteration_limit.
  for (const int limit : {5, 12}) {
    nlohmann::json d = sphere_fit_document();
    d["fit"]["max_evaluations"] = limit;
    const fit::FitResult r =
        setup_fit(parse_experiment(d, testing::experiment_file("").parent_path(), "doc"))
            .calibration->run();
    EXPECT_EQ(r.status, fit::FitStatus::IterationLimit) << r.message;
    EXPECT_NE(r.message.find("(max_evaluations " + std::to_string(limit) + ")"), std::string::npos)
        << r.message;
    // A point's Jacobian here is 5 runs (central differences in 2 parameters):
    // at most the runs of the point under way when the limit came.
    EXPECT_GE(r.forward_runs, limit);
    EXPECT_LE(r.forward_runs, limit + 4) << limit;
    EXPECT_TRUE(r.values.allFinite());
  }
  // BOBYQA stops at it too.
  nlohmann::json d = sphere_fit_document();
  d["fit"]["method"] = "bobyqa";
  d["fit"]["max_evaluations"] = 6;
  const fit::FitResult b =
      setup_fit(parse_experiment(d, testing::experiment_file("").parent_path(), "doc"))
          .calibration->run();
  EXPECT_EQ(b.status, fit::FitStatus::IterationLimit) << b.message;
  EXPECT_NE(b.message.find("max_evaluations"), std::string::npos) << b.message;
}

// Issue 43, "a case is built from its own spec alone", found beside the
// sweep's: a fit's folder holds the run at the fitted values, but its
// experiment.resolved.json (which "repeats this run") said the start's.
TEST(ACaseIsBuiltFromItsOwnSpecAlone, AFitsResolvedExperimentIsItsRunAtTheFittedValues) {
  for (const char* file : {"fit_sphere.json", "fit_synthetic_liver.json"}) {
    const Experiment ex = load_experiment(testing::experiment_file(file));
    const FitSetup setup = setup_fit(ex);
    const fit::FitResult r = setup.calibration->run();
    ASSERT_TRUE(r.success) << r.message;
    const Experiment at_fit = with_fitted_material(ex, *setup.calibration, r);
    const Experiment again =
        parse_experiment(at_fit.resolved, testing::experiment_file("").parent_path(), "resolved");
    const model::Material &fitted = at_fit.simulation().cases.front().model.material,
                          &read = again.simulation().cases.front().model.material;
    for (const std::string& name : fitted.parameter_names())
      EXPECT_EQ(read.parameter(name), fitted.parameter(name)) << file << ": " << name;
    for (size_t k = 0; k < r.names.size(); ++k)  // the fitted values, not the starts
      EXPECT_EQ(read.parameter(r.names[k]), r.values[static_cast<Eigen::Index>(k)]) << file;
    EXPECT_EQ(run_experiment(again).runs[0].summary.unknowns,
              run_experiment(at_fit).runs[0].summary.unknowns)
        << file;
  }
}

TEST(FitConfig, BadFitSectionsAreNamed) {
  nlohmann::json d = sphere_fit_document();
  d["fit"]["mesh_check"] = "sideways";
  expect_fit_error(d, "doc: fit.mesh_check: ");
  d = sphere_fit_document();
  d["fit"]["parameters"][0]["name"] = "stiffness";
  expect_fit_error(d, "doc: fit.parameters[0].name: \"stiffness\" is not a parameter");
  // A fit's figure that names no fitted parameter, once the parameters are good.
  d = sphere_fit_document();
  d["expected"][0]["figure"] = "fit.Yo";
  expect_fit_error(d, "doc: expected[0].figure: no figure \"fit.Yo\" in this experiment");
  d = sphere_fit_document();
  d["fit"]["parameters"][0]["lower"] = 5000;
  expect_fit_error(d, "the start 1000 lies outside the bounds [5000, 1e+06]");
  d = sphere_fit_document();
  d["fit"]["targets"][0]["file"] = "no_such_scan.obj";
  expect_fit_error(d, "doc: fit.targets[0].file");
  d = sphere_fit_document();
  d["fit"]["targets"][0]["step"] = 11;
  expect_fit_error(d, "fit.targets[0].step: load step 11 is beyond the run's 10 steps");
  d = sphere_fit_document();
  d["fit"]["method"] = "newton";
  expect_fit_error(
      d, "fit.method: expected levenberg-marquardt, bobyqa, direct-l, crs2 or multistart");
  // A multi-start search's own fields: only with it, and in range.
  d = sphere_fit_document();
  d["fit"]["starts"] = 4;
  expect_fit_error(d, "fit.starts: only with \"method\": \"multistart\"");
  d = sphere_fit_document();
  d["fit"]["method"] = "multistart";
  d["fit"]["starts"] = 1;
  expect_fit_error(d, "fit.starts");
  d = sphere_fit_document();
  d["fit"]["method"] = "multistart";
  d["fit"]["same_optimum"] = 2;
  expect_fit_error(d, "fit.same_optimum: expected a share of each parameter's range");
  d = sphere_fit_document();
  d["fit"]["objective"] = {{"exclude", {{"where", "z >= -2"}}}};
  expect_fit_error(d, "excludes every vertex");
  d = sphere_fit_document();
  d["fit"]["colour"] = "green";
  expect_fit_error(d, "fit.colour: unknown field");
  d = sphere_fit_document();
  d["fit"]["initial_trust_region_radius"] = 0;
  expect_fit_error(d, "fit.initial_trust_region_radius");
  d = sphere_fit_document();
  d["variants"] = {{{"name", "a"}}};
  expect_fit_error(d, "a fit calibrates one simulation");
}

// Issue 27 and 30: each of these crashed, ended with a solver's internal
// message, or was taken silently; each is a named error before anything runs.
TEST(FitConfig, OptionsAreCheckedOnceForEveryFrontEnd) {
  nlohmann::json d = sphere_fit_document();
  d["fit"]["parameters"][0]["lower"] = 1000;  // lower == upper: Ceres' "infeasible bound"
  d["fit"]["parameters"][0]["upper"] = 1000;
  expect_fit_error(
      d,
      "doc: fit.parameters[0]: parameter \"Y\": expected a lower bound below the upper "
      "one, got [1000, 1000]");
  d = sphere_fit_document();
  d["fit"]["difference_step"] = 5;  // a central-difference run at e^5 times the value: SIGSEGV
  expect_fit_error(
      d,
      "doc: fit.difference_step: expected a step in the fitted variable above 0 and at most 0.5");
  d = sphere_fit_document();
  d["fit"]["objective"] = {{"loss", "huber"}, {"loss_scale", 0}};
  expect_fit_error(d,
                   "doc: fit.objective.loss_scale: expected a positive finite length in m, got 0");
  d = sphere_fit_document();
  d["fit"]["max_iterations"] = 0;
  expect_fit_error(d, "doc: fit.max_iterations: expected 1 to 100000, got 0");
  d = sphere_fit_document();
  d["fit"]["objective"] = {{"loss", "l1"}};
  expect_fit_error(d, "doc: fit.objective.loss: expected squared, huber or cauchy");
  d = sphere_fit_document();
  d["fit"]["targets"][0]["units"] = "mm";
  d["fit"]["targets"][0]["scale"] = 0.001;
  expect_fit_error(d, "fit.targets[0].units: give the scan's units or its scale, not both");
  d = sphere_fit_document();
  d["fit"]["parameters"][0]["name"] = "scale";
  d["fit"]["parameters"][0]["lower"] = -1;
  expect_fit_error(d, "parameter \"scale\": fitted in log scale");
  // The C++ options the same way (the Python module goes through them too).
  fit::FitOptions o;
  o.loss_scale = 0;
  EXPECT_THROW(fit::check_options(o), InputError);
  EXPECT_THROW(fit::method_from_string("newton"), InputError);
}

TEST(FitConfig, AScanInMillimetresIsScaledToMetres) {
  testing::ScratchDir dir;
  const fit::Target m = fit::read_target(testing::data_target("sphere_final.obj"));
  geom::Surface in_mm;
  in_mm.V = 1000.0 * m.points;
  in_mm.F = m.triangles;
  geom::write_obj(dir.path() / "scan_mm.obj", in_mm);
  nlohmann::json d = sphere_fit_document();
  d["fit"]["targets"][0]["file"] = (dir.path() / "scan_mm.obj").string();
  d["fit"]["targets"][0]["units"] = "mm";
  const Experiment ex = parse_experiment(d, testing::experiment_file("").parent_path(), "doc");
  const FitSetup setup = setup_fit(ex);
  EXPECT_TRUE(setup.targets[0].target.points.isApprox(m.points, 1e-15));
  EXPECT_NE(setup.targets[0].target.description.find("scaled by 0.001"), std::string::npos);
  // Without the units the scan lies far from the body: refused, not fitted.
  d["fit"]["targets"][0].erase("units");
  expect_fit_error(d, "scan_mm.obj: the target is 1454.86 times the body's size");
  expect_fit_error(d, "wrong units? (give the scan's \"units\" or \"scale\")");
}

// A nested document (valid JSON, 200 KB) overflowed the stack when copied.
TEST(FitConfig, DeeplyNestedDocumentsAreRefusedWithAShortMessage) {
  testing::ScratchDir dir;
  std::string deep = R"({"name": "deep", "stepping": {"steps": )";
  deep += std::string(100000, '[') + std::string(100000, ']') + "}}";
  const auto file = dir.write("deep.json", deep);
  try {
    load_experiment(file);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("deep.json: nested more than 64 levels deep"), std::string::npos) << what;
    EXPECT_LT(what.size(), 300u);
  }
  // 40 levels are valid JSON within the limit: the field is named, the value quoted short.
  std::string forty = R"({"name": "deep", "surface": {"generator": "icosphere", "subdivisions": 1},
    "material": {"Y": 1000}, "stepping": {"steps": )";
  forty += std::string(40, '[') + std::string(40, ']') + "}}";
  try {
    load_experiment(dir.write("forty.json", forty));
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("stepping.steps: expected"), std::string::npos) << what;
    EXPECT_LT(what.size(), 300u) << what;
  }
}

// A fit's ending is a status, never a silent success.
TEST(FitStatus, ParametersOnTheirBoundsAreNamedWithTheirCorrelation) {
  // gamma held above its truth (3000): Y runs to its lower bound to make up,
  // as a real phantom's Y ran to 1 Pa. Converged, but on bounds.
  nlohmann::json d = sphere_fit_document();
  d["fit"]["parameters"][1]["lower"] = 3500;
  const Experiment ex = parse_experiment(d, testing::experiment_file("").parent_path(), "doc");
  const fit::FitResult r = setup_fit(ex).calibration->run();
  ASSERT_EQ(r.status, fit::FitStatus::ConvergedAtBounds) << r.message << " " << r.status_detail;
  EXPECT_TRUE(r.success);
  EXPECT_EQ(r.at_bounds, (std::vector<std::string>{"Y", "gamma"}));
  EXPECT_NEAR(r.values[0], 10.0, 1e-4);
  EXPECT_NEAR(r.values[1], 3500.0, 1e-4);
  EXPECT_TRUE(std::isnan(r.standard_errors[0]));  // a bound is no estimate
  EXPECT_NE(
      r.status_detail.find("Y = 10 is on its lower bound (its correlation with gamma is -0.9"),
      std::string::npos)
      << r.status_detail;
  EXPECT_EQ(fit_exit_status(r.status), 4);
  EXPECT_TRUE(fit_result_kept(r.status));

  // Held the other way, Y = 2000 below its truth: Y is held on its bound
  // (the active set) while gamma makes up; it converges there and says which
  // parameter sits on it. (Projected steps crept against the bound until the
  // iteration limit.)
  d = sphere_fit_document();
  d["fit"]["parameters"][0]["upper"] = 2000;
  const fit::FitResult limited =
      setup_fit(parse_experiment(d, testing::experiment_file("").parent_path(), "doc"))
          .calibration->run();
  EXPECT_EQ(limited.status, fit::FitStatus::ConvergedAtBounds) << limited.message;
  EXPECT_LT(limited.iterations.size(), 20u);
  EXPECT_EQ(limited.at_bounds, std::vector<std::string>{"Y"});
  EXPECT_NE(limited.status_detail.find("Y = 2000 is on its upper bound"), std::string::npos);
}

TEST(FitStatus, ALoadThatMovesNothingIsNotIdentifiable) {
  nlohmann::json d = sphere_fit_document();
  d["loads"][0]["acceleration"] = {0, 0, 0};
  d["loads"][1]["force"] = {0, 0, 0};
  const Experiment ex = parse_experiment(d, testing::experiment_file("").parent_path(), "doc");
  const fit::FitResult r = setup_fit(ex).calibration->run();
  EXPECT_EQ(r.status, fit::FitStatus::NotIdentifiable) << r.message;
  EXPECT_FALSE(r.success);
  EXPECT_NE(r.status_detail.find("no distance changes with \"Y\""), std::string::npos)
      << r.status_detail;
  EXPECT_EQ(fit_exit_status(r.status), 2);
  EXPECT_FALSE(fit_result_kept(r.status));
  // The report reads every figure without a crash; errors are null.
  testing::ScratchDir dir;
  const FitSetup setup = setup_fit(ex);
  write_fit_files(dir.path(), ex, setup, r, ExperimentResult{});
  std::ifstream in(dir.path() / "fit.json");
  const nlohmann::json report = nlohmann::json::parse(in);
  EXPECT_EQ(report["status"], "not_identifiable");
  EXPECT_TRUE(report["parameters"][0]["standard_error"].is_null());

  // The same class: a difference step too small to move a forward run.
  nlohmann::json tiny = sphere_fit_document();
  tiny["fit"]["jacobian"] = "finite-differences";
  tiny["fit"]["difference_step"] = 1e-300;
  const fit::FitResult t =
      setup_fit(parse_experiment(tiny, testing::experiment_file("").parent_path(), "doc"))
          .calibration->run();
  EXPECT_EQ(t.status, fit::FitStatus::NotIdentifiable) << t.message;
  EXPECT_NE(t.status_detail.find("no distance changes with \"Y\""), std::string::npos)
      << t.status_detail;
}

TEST(FitStatus, TheIterationLimitAndFailedRunsAreCountedByCause) {
  nlohmann::json d = sphere_fit_document();
  d["fit"]["max_iterations"] = 3;
  const Experiment ex = parse_experiment(d, testing::experiment_file("").parent_path(), "doc");
  const FitSetup setup = setup_fit(ex);
  const fit::FitResult r = setup.calibration->run();
  EXPECT_EQ(r.status, fit::FitStatus::IterationLimit) << r.message;
  EXPECT_EQ(fit_exit_status(r.status), 2);
  EXPECT_NE(r.message.find("max_iterations 3"), std::string::npos) << r.message;
  // fit_sphere from 100 times its Y (300 kPa): on its way down, trial
  // points with Y near 19 kPa and gamma near 440 N/m run away (the volume
  // grows past the limit at step 8). Counted under their cause, with their
  // parameters.
  nlohmann::json stiff = sphere_fit_document();
  stiff["material"]["Y"] = 300000.0;
  const fit::FitResult full =
      setup_fit(parse_experiment(stiff, testing::experiment_file("").parent_path(), "doc"))
          .calibration->run();
  ASSERT_EQ(full.status, fit::FitStatus::Converged) << full.message;
  ASSERT_GE(full.failed_runs, 1);
  int counted = 0;
  for (const auto& [cause, count] : full.failures_by_cause) {
    EXPECT_EQ(cause.find_first_of("0123456789"), std::string::npos) << cause;
    counted += count;
  }
  EXPECT_EQ(counted, full.failed_runs);
  ASSERT_FALSE(full.failed_examples.empty());
  EXPECT_NE(full.failed_examples[0].message.find("runaway"), std::string::npos);
  EXPECT_EQ(full.failed_examples[0].values.size(), 2);
  bool told = false;  // the rejected step says why, not "it cost 1.79769e+308"
  for (const fit::IterationRecord& it : full.iterations) told |= !it.trial_failure.empty();
  EXPECT_TRUE(told);
}

TEST(FitStatus, StartFromTakesTheValuesOfAnEarlierFit) {
  testing::ScratchDir dir;
  const auto earlier = dir.write("fit.json", R"({"parameters": [
    {"name": "Y", "value": 2900.5}, {"name": "gamma", "value": 3100.25}]})");
  nlohmann::json d = sphere_fit_document();
  d["fit"]["start_from"] = earlier.string();
  const Experiment ex = parse_experiment(d, testing::experiment_file("").parent_path(), "doc");
  const FitSetup setup = setup_fit(ex);
  EXPECT_EQ(setup.calibration->parameters().parameters()[0].initial, 2900.5);
  EXPECT_EQ(setup.calibration->parameters().parameters()[1].initial, 3100.25);
  const auto partial =
      dir.write("partial.json", R"({"parameters": [{"name": "Y", "value": 2900.5}]})");
  d["fit"]["start_from"] = partial.string();
  expect_fit_error(d, "fit.start_from: " + partial.string() + " has no value for \"gamma\"");
  d["fit"]["start_from"] = (dir.path() / "none.json").string();
  expect_fit_error(d, "none.json: cannot open");
}

TEST(FitConfig, BadForceTargetsAreNamed) {
  nlohmann::json d;
  {
    std::ifstream in(testing::experiment_file("fit_paddles_liver_force.json"));
    d = nlohmann::json::parse(in);
  }
  auto with = [&](const std::function<void(nlohmann::json&)>& edit) {
    nlohmann::json changed = d;
    edit(changed["fit"]["targets"][1]);
    return changed;
  };
  expect_fit_error(with([](nlohmann::json& t) { t["paddle"] = "top"; }),
                   "doc: fit.targets[1].paddle: no paddle is labelled \"top\" (labels: upper, "
                   "lower)");
  expect_fit_error(with([](nlohmann::json& t) { t["support"] = "resting"; }),
                   "fit.targets[1].paddle: expected the label of a paddle, or a support");
  expect_fit_error(with([](nlohmann::json& t) { t["axis"] = "y"; }),
                   "fit.targets[1].axis: a paddle's force is along its own axis");
  expect_fit_error(with([](nlohmann::json& t) {
                     t.erase("paddle");
                     t["support"] = "resting";
                   }),
                   "fit.targets[1].axis: expected one of");
  expect_fit_error(with([](nlohmann::json& t) {
                     t.erase("paddle");
                     t["support"] = "clamp";
                     t["axis"] = "y";
                   }),
                   "fit.targets[1].support: no support is labelled \"clamp\" (labels: resting)");
  expect_fit_error(with([](nlohmann::json& t) { t["travel_units"] = "inch"; }),
                   "fit.targets[1].travel_units: expected one of");
  expect_fit_error(with([](nlohmann::json& t) { t["rows_at"] = "time"; }),
                   "fit.targets[1].rows_at: expected one of");
  expect_fit_error(with([](nlohmann::json& t) { t["weight"] = -1; }),
                   "fit.targets[1].weight: expected a positive number");
  expect_fit_error(with([](nlohmann::json& t) { t["file"] = "missing.csv"; }),
                   "fit.targets[1].file: ");
  expect_fit_error(with([](nlohmann::json& t) { t["type"] = "pressure"; }),
                   "fit.targets[1].type: expected one of");
  expect_fit_error(
      with([](nlohmann::json& t) { t["travel_units"] = "m"; }),
      "row 1: travel 5.92714 m is outside the run's, from 0 to 0.0592714 m");  // mm read as m
  expect_fit_error(with([](nlohmann::json& t) { t["colour"] = "red"; }),
                   "fit.targets[1].colour: unknown field");
  // A measured file's own columns, its range and how its misfit is weighed.
  expect_fit_error(with([](nlohmann::json& t) { t["misfit"] = "squared"; }),
                   "fit.targets[1].misfit: expected one of");
  expect_fit_error(with([](nlohmann::json& t) {
                     t["range"] = {10, 0.5};
                   }),
                   "fit.targets[1].range: expected [from, to] with from <= to");
  expect_fit_error(with([](nlohmann::json& t) { t["range"] = 3; }), "fit.targets[1].range: ");
  expect_fit_error(with([](nlohmann::json& t) { t["force_column"] = "mean_N"; }),
                   "fit.targets[1].file: ");
  expect_fit_error(with([](nlohmann::json& t) { t["force_column"] = "mean_N"; }),
                   "expected a header with the columns mean_N and travel");
  expect_fit_error(with([](nlohmann::json& t) {
                     t["range"] = {500, 600};
                   }),
                   "no row has its travel between 500 and 600");
}

// The shipped Ecoflex experiments read the real files: 39 rows of the mean
// force from 0.5 to 10 mm, each with the ten tests' sd, weighed relatively.
TEST(FitConfig, TheShippedSiliconeFitsReadTheirMeasuredCurve) {
  for (const char* material : {"EF10_0T", "EF50_0T"}) {
    const std::string name = std::string("silicone_") + material + "_fit_half.json";
    const Experiment ex = load_experiment(testing::experiment_file(name));
    const FitSetup setup = setup_fit(ex);
    ASSERT_EQ(setup.force_curves.size(), 1u) << name;
    const fit::ForceCurve& curve = setup.force_curves[0];
    ASSERT_EQ(curve.force.size(), 39u) << name;
    EXPECT_DOUBLE_EQ(curve.at.front(), 0.5e-3);
    EXPECT_DOUBLE_EQ(curve.at.back(), 10e-3);
    EXPECT_EQ(curve.sd.size(), 39u);
    EXPECT_TRUE(curve.relative);
    for (size_t r = 1; r < curve.force.size(); ++r) EXPECT_GT(curve.force[r], curve.force[r - 1]);
  }
}

}  // namespace
}  // namespace fiberfluid::experiment

namespace fiberfluid::experiment {
namespace {

// A calibration over specimens that cannot be set up is named: too few
// specimens, one without a fit, a calibration as a specimen, a shared
// parameter a specimen does not fit, a figure it will not have; and `run`
// is told to use `fit`.
TEST(CalibrationConfig, BadCalibrationsAreNamed) {
  const auto document = [](const char* second) {
    return nlohmann::json{{"name", "two"},
                          {"kind", "calibration"},
                          {"specimens",
                           {{{"name", "synthetic"}, {"experiment", "fit_synthetic_liver.json"}},
                            {{"name", "second"}, {"experiment", second}}}},
                          {"shared", {"Y0", "beta"}}};
  };
  const auto expect_error = [](const nlohmann::json& d, const std::string& part) {
    try {
      const Experiment ex = parse_experiment(d, testing::experiment_file("").parent_path(), "doc");
      setup_joint(ex);
      ADD_FAILURE() << "no error, expected one mentioning '" << part << "'";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
    }
  };
  nlohmann::json d = document("fit_fine_liver.json");
  d["specimens"].erase(1);
  expect_error(d, "doc: specimens: expected two or more specimens");
  expect_error(document("liver_gravity.json"), "has no \"fit\" section");
  expect_error(document("calibrate_two_livers.json"), "not a calibration");
  expect_error(document("no_such_file.json"), "no_such_file.json");
  d = document("fit_fine_liver.json");
  d["shared"] = {"Y0", "rotation_x"};
  expect_error(d, "specimen \"synthetic\" does not fit \"rotation_x\"");
  d = document("fit_fine_liver.json");
  d["shared"] = {"Y0", "Y0"};
  expect_error(d, "doc: shared: \"Y0\" is named twice");
  d = document("fit_fine_liver.json");
  d["expected"] = {{{"figure", "fit.second.gamm"}, {"value", 1}}};
  expect_error(d,
               "no figure \"fit.second.gamm\" in this experiment (expected one of fit.cost, "
               "fit.Y0, fit.beta, fit.synthetic.gamma");

  const Experiment ex = parse_experiment(document("fit_fine_liver.json"),
                                         testing::experiment_file("").parent_path(), "doc");
  ASSERT_EQ(ex.calibration().specimens.size(), 2u);
  EXPECT_THROW(run_experiment(ex), InputError);
  const JointSetup setup = setup_joint(ex);
  EXPECT_EQ(setup.joint->names(),
            (std::vector<std::string>{"Y0", "beta", "synthetic.gamma", "second.gamma"}));
}

// A target of a registered kind (experiment/targets/): tracked markers'
// displacements. The sphere of fit_sphere.json, lighter (density 200, the
// pull 60 N ramped) on the Newton scheme (an analytic Jacobian), run at
// Y = gamma = 3000; two markers' displacements
// at the last step, read from that run, give back both parameters from a
// start a factor 2 and 3 away, and fit.json reports each marker's misfit.
nlohmann::json marker_sphere(double Y, double gamma) {
  nlohmann::json d = sphere_fit_document();
  d.erase("expected");
  d.erase("fit");
  d["material"] = {{"Y", Y}, {"gamma", gamma}};
  d["stepping"] = {{"steps", 5}, {"scheme", "newton"}};
  d["loads"][0]["density"] = 200;
  d["loads"][1]["force"] = {-60, -60, -60};
  d["loads"][1]["schedule"] = "ramp";
  return d;
}

TEST(MarkerTarget, TwoMarkersGiveBackYAndGammaAndReportTheirMisfits) {
  const std::filesystem::path folder = testing::experiment_file("").parent_path();
  const Experiment truth = parse_experiment(marker_sphere(3000.0, 3000.0), folder, "truth");
  const ExperimentResult run = run_experiment(truth);
  ASSERT_TRUE(run.runs_succeeded());
  const Case& c = truth.simulation().cases.front();
  const Eigen::MatrixXd U =
      input_positions(c, run.runs.front().summary.unknowns) - c.input_surface.V;
  nlohmann::json d = marker_sphere(1500.0, 9000.0);
  nlohmann::json targets = nlohmann::json::array();
  for (int vertex : {0, 20}) {  // the pulled vertex, and one elsewhere
    const Eigen::Vector3d u = U.row(vertex).transpose() * 1e3;  // in mm
    nlohmann::json marker = {{"type", "marker"},
                             {"label", "marker " + std::to_string(vertex)},
                             {"units", "mm"},
                             {"displacement", {u.x(), u.y(), u.z()}}};
    if (vertex == 0) {
      marker["vertex"] = vertex;
    } else {  // by its rest position: the nearest vertex is the one there
      const Eigen::Vector3d at = c.input_surface.V.row(vertex).transpose() * 1e3;
      marker["at"] = {at.x(), at.y(), at.z()};
    }
    targets.push_back(marker);
  }
  d["fit"] = {{"targets", targets},
              {"parameters",
               {{{"name", "Y"}, {"lower", 10}, {"upper", 1e6}},
                {{"name", "gamma"}, {"lower", 10}, {"upper", 1e6}}}}};
  const Experiment ex = parse_experiment(d, folder, "markers");
  const FitSetup setup = setup_fit(ex);
  EXPECT_EQ(setup.calibration->num_residuals(), 6);
  EXPECT_TRUE(setup.calibration->analytic_jacobian());
  const fit::FitResult fitted = setup.calibration->run();
  ASSERT_TRUE(fitted.success) << fitted.message;
  EXPECT_NEAR(fitted.values[0], 3000.0, 3e-3);
  EXPECT_NEAR(fitted.values[1], 3000.0, 3e-3);
  ASSERT_EQ(fitted.other_targets.size(), 2u);
  EXPECT_EQ(fitted.other_targets[1].label, "marker 20");
  EXPECT_EQ(fitted.other_targets[1].figures.at("vertex"), 20.0);
  EXPECT_LT(fitted.other_targets[0].figures.at("misfit"), 1e-9);
  EXPECT_NEAR(fitted.other_targets[0].figures.at("simulated_x"), U(0, 0), 1e-9);

  // The analytic Jacobian is the central differences' (issue 30's check).
  const Eigen::VectorXd phi = setup.calibration->parameters().initial_phi();
  const fit::Evaluation analytic = setup.calibration->evaluate(phi, true);
  d["fit"]["jacobian"] = "finite-differences";
  const FitSetup differenced = setup_fit(parse_experiment(d, folder, "markers"));
  const fit::Evaluation central = differenced.calibration->evaluate(phi, true);
  ASSERT_TRUE(analytic.ok && central.ok);
  EXPECT_LT((analytic.jacobian - central.jacobian).norm(), 1e-5 * central.jacobian.norm());

  testing::ScratchDir dir;
  const Experiment at_fit = with_fitted_material(ex, *setup.calibration, fitted);
  write_fit_files(dir.path(), at_fit, setup, fitted, run_experiment(at_fit));
  std::ifstream in(dir.path() / "fit.json");
  const nlohmann::json report = nlohmann::json::parse(in);
  ASSERT_EQ(report["other_targets"].size(), 2u);
  EXPECT_EQ(report["other_targets"][0]["type"], "marker");
  EXPECT_EQ(report["counts"]["other_targets"], 2);
  EXPECT_EQ(report["counts"]["residuals"], 6);
}

TEST(MarkerTarget, BadMarkersAreRefusedNamingTheirField) {
  nlohmann::json d = marker_sphere(3000.0, 3000.0);
  const nlohmann::json parameters = {{{"name", "Y"}, {"lower", 10}, {"upper", 1e6}}};
  auto with_marker = [&](nlohmann::json marker) {
    marker["type"] = "marker";
    if (!marker.contains("displacement")) marker["displacement"] = {0.0, 0.0, -0.1};
    d["fit"] = {{"targets", {marker}}, {"parameters", parameters}};
    return d;
  };
  expect_fit_error(with_marker({{"vertex", 100000}}),
                   "fit.targets[0].vertex: input vertex 100000 is not a vertex of the body");
  expect_fit_error(with_marker({{"vertex", 0}, {"at", {0, 0, 1}}}),
                   "fit.targets[0].vertex: expected the marker's \"vertex\"");
  expect_fit_error(with_marker(nlohmann::json::object()), "fit.targets[0].vertex");
  expect_fit_error(with_marker({{"vertex", 0}, {"step", 6}}),
                   "fit.targets[0].step: step 6 of a run of 5 load steps");
  expect_fit_error(with_marker({{"vertex", 0}, {"displacement", {0.0, 1.0}}}),
                   "fit.targets[0].displacement");
  expect_fit_error(with_marker({{"vertex", 0}, {"colour", "red"}}), "colour");
  // The schema, recorded from the reader, shows every field of the kind.
  const nlohmann::json fields =
      experiment_schema()["properties"]["fit"]["properties"]["targets"]["items"]["properties"];
  for (const char* field : {"vertex", "at", "displacement", "units", "step", "weight", "label"})
    EXPECT_TRUE(fields.contains(field)) << field;
  EXPECT_NE(fields["type"].dump().find("marker"), std::string::npos) << fields["type"];
}

}  // namespace
}  // namespace fiberfluid::experiment
