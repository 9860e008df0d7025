// SPDX-License-Identifier: GPL-3.0-or-later
// Pruning benchmark (issue 4): the time to decide every fiber of concave
// meshes exactly: the liver, torus and Bunny, and a generated torus
// of 5,000 vertices. Prints a Markdown table.
//   fiberfluid_pruning [--skip-large]
#include <cstring>
#include <iostream>
#include <string>

#include "geom/fiber_pruning.hpp"
#include "geom/generators.hpp"
#include "geom/mesh_io.hpp"

namespace {

void report(const std::string& name, const fiberfluid::geom::Surface& s) {
  const fiberfluid::geom::PruningResult r = fiberfluid::geom::prune_fibers(s);
  const std::vector<int> per_vertex = r.mask.kept_per_vertex();
  std::cout << "| " << name << " | " << s.num_vertices() << " | " << r.mask.num_pairs() << " | "
            << r.mask.num_kept() << " | " << r.mask.num_pairs() - r.mask.num_kept() << " | "
            << r.exact_fallbacks << " | " << r.seconds << " |" << std::endl;
}

}  // namespace

int main(int argc, char** argv) {
  namespace geom = fiberfluid::geom;
  const bool skip_large = argc > 1 && std::strcmp(argv[1], "--skip-large") == 0;
  const std::string meshes = FIBERFLUID_MESHES;
  std::cout << "| mesh | vertices | fibers in all | kept | pruned | exact fallbacks | seconds |\n"
            << "|---|---|---|---|---|---|---|" << std::endl;
  for (const char* name : {"liver.obj", "torus.obj", "Bunny.stl"})
    report(name, geom::remove_unused_vertices(geom::read_surface(meshes + "/" + name).surface)
                     .surface);
  if (!skip_large) report("torus R=2 r=0.7, 100 x 50", geom::torus(2.0, 0.7, 100, 50));
  return 0;
}
