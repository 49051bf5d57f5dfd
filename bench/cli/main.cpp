// bvhlab: the command-line front end. Subcommands: info, build, query, policies, run, report, demo; each is
// declared and run in its own file in this folder (cli.hpp).
#include "bench/cli/cli.hpp"

#include <CLI/CLI.hpp>

#include <cstdio>
#include <exception>
#include <vector>

int main(int argc, char** argv) {
  using namespace bvhlab::cli;
  CLI::App app{"bvhlab: collision detection between rigid triangle meshes with BVHs and ADB-trees"};
  app.require_subcommand(1);
  app.footer(
      "Examples:\n"
      "  bvhlab info jeep1.ms3d\n"
      "  bvhlab build teapot.obj --bv aabb --adb --grid 2 --tau 0.25 -o teapot.tree\n"
      "  bvhlab query jeep1.ms3d jeep1.ms3d --normalize --protocol 1.4,100,5000 --strategy adb --p-min 0.9\n"
      "  bvhlab query teapot.tree teapot.tree --pose 1.2,0,0,0,0,1,45 --strategy adb --repeat 1000\n"
      "  bvhlab run bench/scenes/smoke.json -o results/smoke\n"
      "  bvhlab report bench/scenes/demo.json -o report/demo\n"
      "  bvhlab demo --build-dir build/release\n"
      "Meshes are files, or names of bundled (meshes/) and fetched (meshes/fetch.sh) meshes, in their "
      "files'\n"
      "own units unless --normalize applies the protocol normalisation (centre to the origin, longest side "
      "2).\n"
      "Run `bvhlab SUBCOMMAND --help` for a subcommand's options.");
  // The order here is the order of the subcommands in the help.
  const std::vector<Command> commands = {
      add_info_command(app), add_build_command(app),  add_query_command(app), add_policies_command(app),
      add_run_command(app),  add_report_command(app), add_demo_command(app)};

  CLI11_PARSE(app, argc, argv);

  try {
    for (const Command& command : commands)
      if (*command.app) return command.run();
  } catch (const CLI::Error& e) {
    return app.exit(e);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bvhlab: %s\n", e.what());
    return 1;
  }
  return 0;
}
