// retile: the editor, or with a command the command line (cli.h).
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <string>
#include <vector>

#include "cli.h"
#include "cli11.h"
#include "core/process.h"
#include "retile/log.h"

namespace {

const CLI::App* findCommand(const CLI::App& app, const std::string& word) {
  for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; }))
    if (sub->check_name(word)) return sub;
  return nullptr;
}

// CLI11 reports a mistyped command, or an unknown option where a command is due, as "A subcommand
// is required". Walks the words that choose a command and names the one it does not know.
bool unknownCommand(const CLI::App& app, const std::vector<std::string>& args) {
  const CLI::App* at = &app;
  std::string path = app.get_name();
  for (const std::string& word : args) {
    if (at->get_subcommands([](const CLI::App*) { return true; }).empty()) return false;
    const bool option = word.rfind("-", 0) == 0;
    if (option && at->get_option_no_throw(word.substr(0, word.find('='))) != nullptr) return false;
    const CLI::App* next = option ? nullptr : findCommand(*at, word);
    if (!next) {
      std::fprintf(stderr, "%s: unknown %s '%s'\nRun '%s --help' for the commands.\n", path.c_str(), option ? "option" : "command",
                   word.c_str(), path.c_str());
      return true;
    }
    at = next;
    path += " " + word;
  }
  return false;
}

// "retile bench throughput": the command whose options were being read, for the hint to its help.
std::string commandPath(const CLI::App& app) {
  std::string path = app.get_name();
  for (const CLI::App* at = &app; !at->get_subcommands().empty();) {
    at = at->get_subcommands().front();
    path += " " + at->get_name();
  }
  return path;
}

}  // namespace

int main(int argc, char** argv) {
  // Before any thread starts: Qt's Vulkan window creates its own lavapipe device in this thread.
  retile::flushDenormals();
  std::vector<std::string> args(argv + 1, argv + argc);
  if (const char* v = std::getenv("RETILE_LOG"); v && std::strcmp(v, "debug") == 0) retile::setLogLevel(retile::LogLevel::Debug);

  CLI::App app(
      "Retile: an interactive path-traced scene editor that re-renders an edit tile by tile, nearest the edit first.\n"
      "Without a command, `retile [SCENE]` opens the editor on SCENE (the built-in scene without one).",
      "retile");
  app.set_version_flag("-V,--version", "retile " RETILE_VERSION, "print the version and exit");
  app.set_help_flag("-h,--help", "print this help and exit");
  app.require_subcommand(1);
  int status = 0;
  retile::cli::addRender(app, &status);
  retile::cli::addEdit(app, &status);
  retile::cli::addEval(app, &status);
  retile::cli::addCompare(app, &status);
  retile::cli::addBench(app, &status);
  retile::cli::addImport(app, &status);
  // After the commands, which would otherwise inherit it.
  app.footer(
      "SCENE is a file (glTF, OBJ, FBX, PLY, Tungsten scene.json, .retile) or 'default'.\n"
      "`retile COMMAND --help` lists a command's options.");

  try {
    // The editor takes the command line as it is (Qt reads its own options from it): nothing
    // but a scene file, or nothing at all.
    if (args.empty() || (args.size() == 1 && args[0].rfind("-", 0) != 0 && !findCommand(app, args[0])))
      return retile::cli::runEditor(argc, argv, args.empty() ? std::string() : args[0]);
    if (unknownCommand(app, args)) return 2;
    // The commands only: the editor stays at lavapipe's default (core/process.h).
    retile::preferWideCpuVectors();
    app.parse(argc, argv);
    return status;
  } catch (const CLI::ParseError& e) {
    // --help and --version end the parse this way too, with exit code 0.
    if (e.get_exit_code() == 0) return app.exit(e);
    const std::string command = commandPath(app);
    std::fprintf(stderr, "%s: error: %s\nRun '%s --help' for its options.\n", command.c_str(), e.what(), command.c_str());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
}
