// retile: the editor (issue 4 brings it) and the command line.
#include <cstdio>
#include <cstring>
#include <exception>
#include <string>
#include <vector>

#include "cli.h"
#include "retile/log.h"

namespace {

void usage() {
  std::fprintf(stderr,
               "usage:\n"
               "  retile [SCENE]                      opens the editor (the built-in scene without SCENE)\n"
               "  retile render SCENE [--size WxH] [--spp N] [--seed S] [--max-bounces B] [--out FILE.exr|png]\n"
               "                      [--view Standard|Filmic] [--exposure STOPS] [--denoise]\n"
               "  retile edit SCENE --script EDITS.json --method NAME --out-dir DIR [--size WxH] [--tile T]\n"
               "                    [--quality Q|auto] [--smooth] [--stale-cap N] [--converge SPP] [--reference SPP]\n"
               "                    [--denoise [--denoise-threshold PX] [--no-soft-borders]] [--reuse [--reuse-rate A]] [--no-images]\n"
               "  retile eval [SCENE ...] --out-dir DIR [--quick] [--size WxH] [--methods LIST] [--scenarios LIST]\n"
               "                    [--script FILE ...] [--reference-spp N] [--every K] [--converge SPP] [--target REL]\n"
               "  retile eval [SCENE ...] --stability --out-dir DIR [--quick] [--size WxH] [--cases LIST] [--methods LIST]\n"
               "  retile bench throughput SCENE [--size WxH] [--frames N] [--max-bounces B]\n"
               "  retile bench bvh [--triangles N] | edit | frames SCENE [--drag] | denoise [SCENE] [--size WxH]\n"
               "               | scale [--size WxH] [--frames N]\n"
               "  retile compare IMAGE REFERENCE [--noise IMAGE2] [--block N] [--exclude X,Y,W,H ...] [--worst K]\n"
               "  retile import FILE\n"
               "  retile --version | --help\n"
               "SCENE is a file (glTF, OBJ, FBX, PLY, Tungsten scene.json, .retile) or 'default'.\n");
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  if (const char* v = std::getenv("RETILE_LOG"); v && std::strcmp(v, "debug") == 0) retile::setLogLevel(retile::LogLevel::Debug);
  try {
    if (args.empty() || (args.size() == 1 && args[0].rfind("-", 0) != 0 && !retile::cli::isCommand(args[0])))
      return retile::cli::runEditor(argc, argv, args.empty() ? std::string() : args[0]);
    if (args[0] == "--help" || args[0] == "-h" || args[0] == "help") {
      usage();
      return 0;
    }
    if (args[0] == "--version" || args[0] == "-V") {
      std::printf("retile %s\n", RETILE_VERSION);
      return 0;
    }
    std::string cmd = args[0];
    std::vector<std::string> rest(args.begin() + 1, args.end());
    if (cmd == "render") return retile::cli::runRender(rest);
    if (cmd == "bench") return retile::cli::runBench(rest);
    if (cmd == "import") return retile::cli::runImport(rest);
    if (cmd == "edit") return retile::cli::runEdit(rest);
    if (cmd == "eval") return retile::cli::runEval(rest);
    if (cmd == "compare") return retile::cli::runCompare(rest);
    std::fprintf(stderr, "retile: unknown command '%s'\n", cmd.c_str());
    usage();
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
}
