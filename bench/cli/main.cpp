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
      "Run `bvhlab SUBCOMMAND --help` for a subcommand's options.\n"
      "Exit status: 0 done; 1 failed (a bad file, scene or value, or the work failed); 2 a bad command line\n"
      "(unknown or missing option, a value out of range, an output path that cannot be written); run and\n"
      "report also 3 when the ground truth disagrees with CGAL, report 4 when the figures could not be "
      "drawn.\n"
      "Every message starts with \"bvhlab:\".");
  // The order here is the order of the subcommands in the help.
  const std::vector<Command> commands = {
      add_info_command(app), add_build_command(app),  add_query_command(app), add_policies_command(app),
      add_run_command(app),  add_report_command(app), add_demo_command(app)};

  try {
    app.parse(argc, argv);
    for (const Command& command : commands)
      if (*command.app) return command.run();
  } catch (const CLI::Error& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help: the help on stdout
    std::fprintf(stderr, "bvhlab: %s\nRun with --help for more information.\n", e.what());
    return kBadCommandLine;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bvhlab: %s\n", e.what());
    return kFailed;
  }
  return 0;
}
