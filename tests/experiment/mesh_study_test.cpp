// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/experiment/run/mesh_study.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <csignal>
#include <fstream>
#include <thread>

#include "../app/cli_support.hpp"
#include "../test_support.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::experiment {
namespace {

using json = nlohmann::json;

TEST(MeshStudy, RichardsonFindsTheOrderAndTheLimitOfASmoothSequence) {
  // f(h) = 2 + 0.3 h^2 - 0.1 h^3 is dominated by its h^2 term: on h = 1, 1/1.5,
  // 1/2.25 and on the unequal h = 1, 0.6, 0.35 the order is near 2 and the
  // extrapolation far closer to 2 than the finest value.
  const auto f = [](double h) { return 2.0 + 0.3 * h * h - 0.01 * h * h * h; };
  for (const auto& h :
       {std::vector<double>{1.0, 1.0 / 1.5, 1.0 / 2.25}, std::vector<double>{1.0, 0.6, 0.35}}) {
    const RichardsonEstimate e = richardson(f(h[0]), f(h[1]), f(h[2]), h[0], h[1], h[2]);
    EXPECT_TRUE(e.monotone);
    EXPECT_NEAR(e.order, 2.0, 0.1);
    EXPECT_LT(std::abs(e.extrapolated - 2.0), 0.05 * std::abs(f(h[2]) - 2.0));
    EXPECT_NEAR(e.error, std::abs(e.extrapolated - f(h[2])), 1e-15);
  }
  // Exactly second order: exact.
  const RichardsonEstimate exact = richardson(1.0 + 1.0, 1.0 + 0.25, 1.0 + 0.0625, 1.0, 0.5, 0.25);
  EXPECT_NEAR(exact.order, 2.0, 1e-10);
  EXPECT_NEAR(exact.extrapolated, 1.0, 1e-12);
  // Changes of both signs have no order: the last change is the estimate.
  const RichardsonEstimate oscillating = richardson(1.0, 1.1, 1.05, 1.0, 0.5, 0.25);
  EXPECT_FALSE(oscillating.monotone);
  EXPECT_EQ(oscillating.trend, metrics::Trend::Oscillating);
  EXPECT_TRUE(std::isnan(oscillating.order));
  EXPECT_NEAR(oscillating.error, 0.05, 1e-12);
}

// Issue 59, class 1 ("no success without a result"): a figure that does not
// change has no order (it was "order 0.00"); changes that grow are not
// converging, whatever Celik's absolute value makes of them (a diverging
// figure was "order 7.31" with an extrapolation); and the trend is over
// every level, not the three finest.
TEST(MeshStudy, NoOrderWithoutConvergence) {
  const RichardsonEstimate constant = richardson(0.001, 0.001, 0.001, 1.0, 0.5, 0.25);
  EXPECT_EQ(constant.trend, metrics::Trend::Constant);
  EXPECT_TRUE(std::isnan(constant.order));
  EXPECT_EQ(constant.extrapolated, 0.001);
  EXPECT_EQ(constant.error, 0.0);
  // 1e-16 apart: rounding, still constant.
  EXPECT_EQ(richardson(0.3, 0.1 + 0.2, 0.3, 1.0, 0.5, 0.25).trend, metrics::Trend::Constant);

  // Changes of one sign that grow: 1, 1.1, 1.3 (0.1, then 0.2).
  const RichardsonEstimate growing = richardson(1.0, 1.1, 1.3, 1.0, 0.5, 0.25);
  EXPECT_EQ(growing.trend, metrics::Trend::NotConverging);
  EXPECT_TRUE(growing.monotone);
  EXPECT_TRUE(std::isnan(growing.order));
  EXPECT_TRUE(std::isnan(growing.extrapolated));
  EXPECT_TRUE(std::isnan(growing.error));
  // Equal changes do not shrink either.
  EXPECT_EQ(richardson(1.0, 1.5, 2.0, 1.0, 0.5, 0.25).trend, metrics::Trend::NotConverging);

  // The organ of the issue: -3.5%, +10.8%, +0.09% over four levels. Its three
  // finest alone look monotone with an order; over every level it oscillates.
  std::vector<double> organ = {1.0};
  for (double change : {-0.035, 0.108, 0.0009}) organ.push_back(organ.back() * (1.0 + change));
  const std::vector<double> sizes = {1.0, 1.0 / 1.5, 1.0 / 2.25, 1.0 / 3.375};
  ASSERT_TRUE(
      std::isfinite(richardson(organ[1], organ[2], organ[3], sizes[1], sizes[2], sizes[3]).order));
  const RichardsonEstimate whole = richardson(organ, sizes);
  EXPECT_EQ(whole.trend, metrics::Trend::Oscillating);
  EXPECT_TRUE(std::isnan(whole.order));
  // A cylinder whose last change is larger than the one before: 0.010, 0.004, 0.006.
  const RichardsonEstimate cylinder = richardson({0.150, 0.140, 0.136, 0.130}, sizes);
  EXPECT_EQ(cylinder.trend, metrics::Trend::NotConverging);
  EXPECT_TRUE(std::isnan(cylinder.order));
  // Shrinking over all four: the order from the three finest, as before.
  const auto f = [](double h) { return 2.0 + 0.3 * h * h; };
  const RichardsonEstimate smooth =
      richardson({f(sizes[0]), f(sizes[1]), f(sizes[2]), f(sizes[3])}, sizes);
  EXPECT_EQ(smooth.trend, metrics::Trend::Converging);
  EXPECT_NEAR(smooth.order, 2.0, 1e-9);
  EXPECT_NEAR(smooth.extrapolated, 2.0, 1e-12);
}

// A small box, clamped at x = 0, one vertex pulled 1 mm up by index.
json pulled_box(const std::vector<int>& segments) {
  return {
      {"name", "box"},
      {"surface",
       {{"generator", "box"},
        {"min", {0, 0, 0}},
        {"max", {0.04, 0.02, 0.02}},
        {"segments", segments}}},
      {"material", {{"Y", 100000}, {"gamma", 0}}},
      {"supports", {{{"label", "clamp"}, {"where", "x <= 0"}}}},
      {"prescribed", {{{"label", "pull"}, {"vertices", {30}}, {"displacement", {0, 0, 0.001}}}}},
      {"stepping", {{"steps", 2}}}};
}

std::string refusal_of(const std::filesystem::path& file, const MeshStudySpec& spec) {
  try {
    run_mesh_study(file, spec);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// Issue 59, class 1: an index names another point at each level (a box's
// vertex 30 landed on the clamp at [16, 8, 8]). Every index the experiment
// names is mapped to the same point of each level: the pulled vertex's
// displacement is its prescribed 1 mm at every level, and the vertex 30 of
// the coarsest, at (0.02, 0.02, 0), is some other index at the finer ones.
// Where a level lacks the point, the study is refused naming the field.
TEST(MeshStudy, AVertexIndexNamesTheSamePointAtEveryLevel) {
  const testing::ScratchDir dir;
  const auto file = dir.write("box.json", pulled_box({4, 2, 2}).dump());
  MeshStudySpec spec;
  spec.ratio = 2.0;
  spec.figures = {"displacement.30.z", "position.30.x", "position.30.y"};
  const MeshStudy study = run_mesh_study(file, spec);
  ASSERT_EQ(study.figures.size(), 3u);
  EXPECT_EQ(study.figures[0].values, std::vector<double>(3, 0.001));
  EXPECT_EQ(study.figures[0].estimate.trend, metrics::Trend::Constant);
  for (double x : study.figures[1].values) EXPECT_NEAR(x, 0.02, 1e-15);
  for (double y : study.figures[2].values) EXPECT_NEAR(y, 0.02, 1e-15);
  ASSERT_EQ(study.sizes.size(), 3u);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(study.sizes[k], std::pow(0.5, k), 1e-14);

  spec.ratio = 1.5;  // [9, 5, 5] at level 3: x = 0.02 is no vertex
  const std::string refused = refusal_of(file, spec);
  EXPECT_NE(refused.find("prescribed[0].vertices[0]: input vertex 30 at (0.02, 0.02, 0) is no "
                         "vertex of level 3 (segments [9, 5, 5])"),
            std::string::npos)
      << refused;
  // A figure that is none, or a fit's: refused before any level runs.
  spec.ratio = 2.0;
  spec.figures = {"max_displacemnt"};
  EXPECT_NE(refusal_of(file, spec).find("--figure: no figure \"max_displacemnt\""),
            std::string::npos);
  spec.figures = {"fit.cost"};
  EXPECT_NE(refusal_of(file, spec).find("not its fit"), std::string::npos);
}

// Issue 59, class 1: levels that rounding leaves identical gave an error of
// 0, and sizes came from the first segment count alone ([5, 3, 3] ->
// [6, 3, 3] refined along x only, reported uniform). Every count must grow,
// and the size is the surface's mean element size.
TEST(MeshStudy, EveryLevelRefinesEveryDirection) {
  const testing::ScratchDir dir;
  MeshStudySpec spec;
  spec.ratio = 1.1;
  json box = pulled_box({5, 3, 3});
  box["prescribed"][0].erase("vertices");
  box["prescribed"][0]["where"] = "x >= 0.04";
  std::string refused = refusal_of(dir.write("b533.json", box.dump()), spec);
  EXPECT_NE(refused.find("surface.segments: a ratio of 1.1 refines segments [5, 3, 3] to segments "
                         "[6, 3, 3] at level 2, leaving a count as it was"),
            std::string::npos)
      << refused;
  EXPECT_NE(refused.find("at least 1.23"), std::string::npos) << refused;
  box["surface"]["segments"] = {5, 5, 5};
  refused = refusal_of(dir.write("b555.json", box.dump()), spec);
  EXPECT_NE(refused.find("--ratio: a ratio of 1.1 leaves level 3 as level 2 (segments [6, 6, 6])"),
            std::string::npos)
      << refused;
  // [4, 2, 2] by 1.5: [6, 3, 3], [9, 5, 5]; the size is sqrt(area / faces),
  // not 4 / 9 from the first count.
  box["surface"]["segments"] = {4, 2, 2};
  spec.ratio = 1.5;
  spec.figures = {"max_displacement"};
  const MeshStudy study = run_mesh_study(dir.write("b422.json", box.dump()), spec);
  const auto h = [](double faces) { return std::sqrt(0.0040 / faces); };
  const double faces[] = {2 * (8 + 8 + 4), 2 * (18 + 18 + 9), 2 * (45 + 45 + 25)};
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(study.sizes[k], h(faces[k]) / h(faces[0]), 1e-12) << k;
}

// Issue 59, class 2: a level that fails keeps the levels before it (a fourth
// level failing after 9.5 minutes left nothing of the first three), in
// DIR.failed with the reason, exit 2; --max-memory covers every level.
TEST(MeshStudy, ALevelThatFailsKeepsTheLevelsBeforeIt) {
  const testing::ScratchDir dir;
  std::ifstream in(testing::experiment_file("sphere.json"));
  json sphere = json::parse(in);
  sphere.erase("expected");
  sphere["surface"]["subdivisions"] = 1;
  const auto file = dir.write("sphere.json", sphere.dump());
  // Dense LU: about 20 MiB at subdivisions 1 and 2, 48 MiB at 3.
  const testing::Outcome outcome =
      testing::run_cli("study mesh " + file.string() +
                       " --ratio 2 --levels 4 --figure max_displacement --max-memory 40M -o " +
                       (dir.path() / "study").string());
  EXPECT_EQ(outcome.status, 2) << outcome.output;
  EXPECT_NE(outcome.output.find("level 3, subdivisions 3]: this case needs about"),
            std::string::npos)
      << outcome.output;
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "study"));
  std::ifstream study_file(dir.path() / "study.failed" / "study.json");
  const json study = json::parse(study_file);
  EXPECT_EQ(study["levels"], 4);
  EXPECT_EQ(study["levels_run"], 2);
  EXPECT_EQ(study["figures"]["max_displacement"]["values"].size(), 2u);
  EXPECT_TRUE(study["figures"]["max_displacement"]["trend"].is_null());
  EXPECT_NE(study["failure"].get<std::string>().find("--max-memory"), std::string::npos);
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "study.failed" / "FAILED"));
}

// Issue 59, class 2: Ctrl-C during a study exits 130 (it was 1, "the run
// failed") and writes nothing.
TEST(MeshStudy, CtrlCStopsTheStudy) {
  const testing::ScratchDir dir;
  json box = pulled_box({4, 2, 2});
  box["stepping"]["steps"] = 4000;
  const auto file = dir.write("box.json", box.dump());
  const pid_t pid = testing::start_cli(
      {"study", "mesh", file.string(), "--ratio", "2", "-o", (dir.path() / "study").string()},
      dir.path() / "study.log");
  for (int wait = 0; wait < 600; ++wait) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    if (testing::read_file(dir.path() / "study.log").find("level 2 of 3") != std::string::npos)
      break;
  }
  ASSERT_NE(testing::read_file(dir.path() / "study.log").find("level 2 of 3"), std::string::npos);
  kill(pid, SIGINT);
  double seconds = 0.0;
  EXPECT_EQ(testing::wait_for(pid, &seconds), 130) << testing::read_file(dir.path() / "study.log");
  EXPECT_LT(seconds, 10.0);
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "study"));
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "study.failed"));
}

TEST(MeshStudy, RefinesWhatTheFileGivesAndNamesWhatItLacks) {
  std::string resolution;
  double factor = 0.0;
  json cylinder = {{"surface", {{"generator", "cylinder"}, {"segments", {18, 16}}}},
                   {"fem_reference", {{"E", 1000}, {"nu", 0.3}, {"size", 0.01}}}};
  json refined = refined_document(cylinder, StudiedMesh::Surface, 1.5, &resolution, &factor);
  EXPECT_EQ(refined["surface"]["segments"], json({27, 24}));
  EXPECT_EQ(resolution, "segments [27, 24]");
  EXPECT_DOUBLE_EQ(factor, 1.5);
  refined = refined_document(cylinder, StudiedMesh::FemReference, 2.0, &resolution, &factor);
  EXPECT_DOUBLE_EQ(refined["fem_reference"]["size"].get<double>(), 0.005);
  EXPECT_EQ(refined["surface"], cylinder["surface"]);  // the surface kept
  json file = {{"surface", {{"file", "liver.obj"}, {"remesh_vertices", 1000}}}};
  refined = refined_document(file, StudiedMesh::Surface, 2.0, &resolution, &factor);
  EXPECT_EQ(refined["surface"]["remesh_vertices"], 4000);  // vertices as h^-2
  EXPECT_DOUBLE_EQ(factor, 2.0);
  // A generator's surface remeshed: the remeshing sets the resolution, so a
  // ratio that is no power of 2 refines it and leaves the subdivisions.
  json remeshed = {
      {"surface", {{"generator", "icosphere"}, {"subdivisions", 5}, {"remesh_vertices", 600}}}};
  refined = refined_document(remeshed, StudiedMesh::Surface, 1.25, &resolution, &factor);
  EXPECT_EQ(refined["surface"]["remesh_vertices"], 938);
  EXPECT_EQ(refined["surface"]["subdivisions"], 5);
  EXPECT_EQ(resolution, "remesh_vertices 938");
  const auto refusal = [&](const json& document, StudiedMesh mesh, double by) {
    try {
      refined_document(document, mesh, by, &resolution, &factor);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(refusal({{"surface", {{"file", "liver.obj"}}}}, StudiedMesh::Surface, 2.0)
                .find("surface: expected the resolution"),
            std::string::npos);
  EXPECT_NE(refusal({{"surface", {{"generator", "icosphere"}, {"subdivisions", 2}}}},
                    StudiedMesh::Surface, 1.5)
                .find("surface.subdivisions: refines by factors of 2"),
            std::string::npos);
  EXPECT_NE(refusal(file, StudiedMesh::FemReference, 2.0).find("fem_reference.size"),
            std::string::npos);
}

TEST(MeshStudy, TheCommandPrintsTheOrderAndWritesTheStudy) {
  const testing::ScratchDir dir;
  std::ifstream in(testing::experiment_file("sphere.json"));
  json sphere = json::parse(in);
  sphere["surface"]["subdivisions"] = 1;
  sphere.erase("expected");
  sphere["surface"]["radius"] = 1.0;
  const auto file = dir.write("sphere.json", sphere.dump());
  const testing::Outcome outcome = testing::run_cli(
      "study mesh " + file.string() + " --ratio 2 --figure max_displacement --plot -o " +
      (dir.path() / "study").string());
  ASSERT_EQ(outcome.status, 0) << outcome.output;
  EXPECT_NE(outcome.output.find("level 3: subdivisions 3"), std::string::npos) << outcome.output;
  std::ifstream study_file(dir.path() / "study" / "study.json");
  const json study = json::parse(study_file);
  const json& figure = study["figures"]["max_displacement"];
  ASSERT_EQ(figure["values"].size(), 3u);
  EXPECT_TRUE(figure["monotone"].get<bool>());
  EXPECT_EQ(figure["trend"], "converging");
  EXPECT_GT(figure["observed_order"].get<double>(), 1.0);  // the paper's sphere: about 1.6
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "study" / "study.csv"));
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "study" / "plot.png")) << outcome.output;
  // Run again into the same folder: replaced whole. Into a folder fiberfluid
  // did not write: refused before anything runs, the folder kept.
  const testing::Outcome again =
      testing::run_cli("study mesh " + file.string() + " --ratio 2 --figure max_displacement -o " +
                       (dir.path() / "study").string());
  EXPECT_EQ(again.status, 0) << again.output;
  dir.write("notes.txt", "mine");
  const testing::Outcome foreign =
      testing::run_cli("study mesh " + file.string() + " --ratio 2 -o " + dir.path().string());
  EXPECT_NE(foreign.status, 0);
  EXPECT_EQ(foreign.output.find("level 1 of 3"), std::string::npos) << foreign.output;
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "notes.txt"));
  // A file it cannot refine: named, exit status of bad input.
  sphere["surface"].erase("subdivisions");
  const auto bare = dir.write("bare.json", sphere.dump());
  const testing::Outcome refused = testing::run_cli("study mesh " + bare.string() + " --ratio 2");
  EXPECT_NE(refused.status, 0);
  EXPECT_NE(refused.output.find("surface: expected the resolution"), std::string::npos)
      << refused.output;
}

// fit.mesh_check: the paper's sphere fitted exactly on its own mesh
// (subdivisions 2) and again on the next coarser (1): the coarse sphere needs
// other parameters, and the shift, far beyond the exact fit's interval, is
// reported and warned of.
// Issue 44, "fibers whose parameters converge": the soft cylinder under its
// weight at fixed parameters (central fibers within 5 cm, the clamp's mirror
// layer, 4 Newton steps) on segments [18, 16], [23, 20], [28, 25]. With the
// paper's count and a constant influence its largest displacement jumps
// (0.1344, 0.1239, 0.1282 m: the cap's rings and the horizon's edge take in
// vertices unevenly as the mesh changes); with the central fibers' defaults
// (the area count and the conical influence) it falls monotonically by
// shrinking steps (0.14443, 0.14350, 0.14340 m; at [35, 31] 0.14321).
TEST(MeshStudy, CentralFibersByDefaultConvergeMonotonicallyWithTheMesh) {
  testing::ScratchDir dir;
  nlohmann::json doc = nlohmann::json::parse(R"({
    "name": "cylinder_study",
    "surface": {"generator": "cylinder", "radius": 0.02, "length": 0.18, "segments": [18, 16]},
    "material": {"Y": 100000, "gamma": 0},
    "fibers": {"kinematics": "central", "horizon": 0.05},
    "supports": [{"label": "clamp", "where": "x <= 0", "layer": "mirror"}],
    "loads": [{"type": "gravity", "acceleration": [0, 0, -9.81], "density": 1000,
               "integration": "exact"}],
    "stepping": {"scheme": "newton", "steps": 4}
  })");
  MeshStudySpec spec;
  spec.ratio = 1.25;
  spec.figures = {"max_displacement"};
  const auto study = [&](const nlohmann::json& d) {
    const MeshStudy s = run_mesh_study(dir.write("study.json", d.dump()), spec);
    return s.figures.at(0).values;
  };
  const std::vector<double> converging = study(doc);
  ASSERT_EQ(converging.size(), 3u);
  EXPECT_NEAR(converging[0], 0.14443, 2e-5);
  EXPECT_GT(converging[0], converging[1]);
  EXPECT_GT(converging[1], converging[2]);
  EXPECT_LT(converging[1] - converging[2], converging[0] - converging[1]);
  EXPECT_LT((converging[1] - converging[2]) / converging[2], 0.003);

  doc["fibers"]["connection_count"] = "symmetric";
  doc["fibers"]["influence"] = "constant";
  const std::vector<double> paper = study(doc);
  EXPECT_NEAR(paper[0], 0.13439, 2e-5);
  EXPECT_LT(paper[1], paper[0]);  // down by 8%, then up by 3%: not monotone
  EXPECT_GT(paper[2], paper[1]);
}

// Issue 44's sphere under gravity (experiments/dome_mesh_study.json): the
// octahedron's half sphere hanging from its wall, whose edge is split and
// whose counts mix by their mean. Subdivisions 2 to 5: 1.3558, 1.4321,
// 1.4725, 1.4843 mm, monotone, order 1.77, the two finest 0.80% apart. With
// the edge held, the area count and the exact load (the study before the
// split) the order was 1.16 and the two finest 3.0% apart (docs/model.md).
TEST(MeshStudy, TheSphereUnderGravityConvergesWithItsEdgeSplit) {
  MeshStudySpec spec;
  spec.levels = 4;
  spec.ratio = 2.0;
  spec.figures = {"max_displacement"};
  const MeshStudy s = run_mesh_study(testing::experiment_file("dome_mesh_study.json"), spec);
  const std::vector<double>& v = s.figures.at(0).values;
  ASSERT_EQ(v.size(), 4u);
  const std::vector<double> expected = {1.35577e-3, 1.43211e-3, 1.47248e-3, 1.48435e-3};
  for (size_t k = 0; k < v.size(); ++k) EXPECT_NEAR(v[k], expected[k], 1e-8) << k;
  for (size_t k = 1; k < v.size(); ++k) EXPECT_GT(v[k], v[k - 1]);
  EXPECT_LT((v[3] - v[2]) / v[3], 0.01);
  const RichardsonEstimate finest = richardson(v[1], v[2], v[3], 0.5, 0.25, 0.125);
  EXPECT_TRUE(finest.monotone);
  EXPECT_GT(finest.order, 1.5);
}

TEST(FitMeshCheck, AFitReportsHowFarItsParametersMoveOnACoarserMesh) {
  const testing::ScratchDir dir;
  std::ifstream in(testing::experiment_file("fit_sphere.json"));
  json fit = json::parse(in);
  fit["fit"]["mesh_check"] = "coarser";
  fit.erase("expected");
  fit["fit"]["targets"][0]["file"] = (testing::experiment_file("fit_sphere.json").parent_path() /
                                      fit["fit"]["targets"][0]["file"].get<std::string>())
                                         .string();
  const auto file = dir.write("fit.json", fit.dump());
  const testing::Outcome outcome =
      testing::run_cli("fit " + file.string() + " -q -o " + (dir.path() / "out").string());
  ASSERT_EQ(outcome.status, 0) << outcome.output;
  EXPECT_NE(outcome.output.find("mesh check (subdivisions 1"), std::string::npos) << outcome.output;
  EXPECT_NE(outcome.output.find("warning: the mesh moves gamma further than its statistical"),
            std::string::npos)
      << outcome.output;
  std::ifstream summary_file(dir.path() / "out" / "summary.json");
  const json figures = json::parse(summary_file)["figures"];
  EXPECT_NEAR(figures["fit.gamma"].get<double>(), 3000.0, 1e-3);  // the fit itself: exact
  const double shift = figures["fit.mesh_shift.gamma"].get<double>();
  EXPECT_GT(std::abs(shift), 10.0);
  EXPECT_NEAR(figures["fit.mesh_check.gamma"].get<double>(),
              figures["fit.gamma"].get<double>() + shift, 1e-9);
  // fit.json records the check: its mesh, how its fit ended, the values there.
  std::ifstream report_file(dir.path() / "out" / "fit.json");
  const json check = json::parse(report_file)["mesh_check"];
  EXPECT_EQ(check["mesh"], "coarser");
  EXPECT_EQ(check["resolution"], "subdivisions 1");
  EXPECT_FALSE(check["status"].get<std::string>().empty());
  EXPECT_NEAR(check["parameters"]["gamma"]["shift"].get<double>(), shift, 1e-9);

  // Issue 59, class 2: a check whose mesh is refused threw away the
  // converged fit (exit 1, nothing written). It is posed before the fit now:
  // the pull on vertex 100, which the coarser icosphere (42 vertices) lacks,
  // is refused naming the field before any fitting. Vertex 0 is the same
  // point on both meshes, so the check above pulls where the fit does.
  fit["loads"][1]["vertex"] = 100;
  const testing::Outcome refused =
      testing::run_cli("fit " + dir.write("fit100.json", fit.dump()).string() + " -o " +
                       (dir.path() / "out100").string());
  EXPECT_EQ(refused.status, 1) << refused.output;
  EXPECT_NE(refused.output.find("fit.mesh_check: "), std::string::npos) << refused.output;
  EXPECT_NE(refused.output.find("loads[1].vertex: input vertex 100 at"), std::string::npos)
      << refused.output;
  EXPECT_EQ(refused.output.find("iteration"), std::string::npos) << refused.output;
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "out100"));
}

}  // namespace
}  // namespace fiberfluid::experiment
