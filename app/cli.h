// The command line: `retile render`, `retile edit`, `retile eval`, `retile compare`, `retile bench`, `retile import`,
// one CLI11 tree that main() builds and parses. Everything here runs on the main thread.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "retile/error.h"
#include "retile/io.h"

namespace CLI {
class App;
class Option;
class Validator;
}  // namespace CLI

namespace retile::cli {

// Each adds its command to `app`, the options declared beside the code that reads them. When the
// command is chosen, its callback runs it (inside App::parse, after every option was read and
// checked) and leaves the exit status in *status. A problem with the command line found in the
// callback (options that go together) is thrown as a CLI::ParseError, so it is reported like one.
void addRender(CLI::App& app, int* status);
void addEdit(CLI::App& app, int* status);
void addEval(CLI::App& app, int* status);
void addCompare(CLI::App& app, int* status);
void addImport(CLI::App& app, int* status);
// `retile bench frames` and `retile bench rest`, under `bench` (cli_bench_editor.cpp).
void addEditorBenches(CLI::App& bench, int* status);
void addBench(CLI::App& app, int* status);  // bench throughput, bvh, edit, frames, denoise, scale

// The Qt editor on `file` ("" or "default": the built-in scene). Needs a display.
int runEditor(int argc, char** argv, const std::string& file);

// ---- Options, for the add* functions ----
//
// Numbers are read as files read them (std::from_chars, core/numbers.h), never by CLI11's own
// conversion: that uses strtold, which follows the process locale (under de_DE, once Qt has set
// it, "0.5" stops at the '.'), and strtoll in base 0, which reads "010" as 8. A bad value is
// refused with the option's name, e.g. "--spp: 'abc' is not a whole number" or
// "--spp: 0 is outside 1..1048576". The help line gets the range and, where `out` holds one,
// the default appended.

struct ImageSize {
  int width = 0, height = 0;
};

CLI::Option* addInt(CLI::App& app, const std::string& name, int* out, int lo, int hi, const std::string& help);
CLI::Option* addNumber(CLI::App& app, const std::string& name, double* out, double lo, double hi, const std::string& help);
// --size WxH, each side 1..kMaxImageSide.
CLI::Option* addSize(CLI::App& app, ImageSize* out, const std::string& help);
// Without the option `out` stays empty; `otherwise` says what is used then ("the scene's").
CLI::Option* addInt(CLI::App& app, const std::string& name, std::optional<int>* out, int lo, int hi, const std::string& help,
                    const std::string& otherwise);
CLI::Option* addNumber(CLI::App& app, const std::string& name, std::optional<double>* out, double lo, double hi, const std::string& help,
                       const std::string& otherwise);
CLI::Option* addSize(CLI::App& app, std::optional<ImageSize>* out, const std::string& help, const std::string& otherwise);
// A positional SCENE: a file any importer reads, or "default".
CLI::Option* addScene(CLI::App& app, std::string* out);
// Refuses a value that is not one of `names`; `what` names their kind in the message ("method").
CLI::Validator oneOf(const std::string& what, const std::vector<std::string>& names);
// A whole number lo..hi, or the message saying why `text` is not one (without the option's name).
Result<int> readInt(const std::string& text, int lo, int hi);

// "default" is the built-in scene; anything else a file any importer reads.
Result<ImportedScene> loadScene(const std::string& name);

// Prints the renderer's warnings about a scene, leaving out files the import already reported.
void printRenderWarnings(const std::vector<std::string>& renderWarnings, const std::vector<std::string>& importWarnings);
// A one-line progress bar on stderr, redrawn in place (a line per tenth when not a terminal).
void progressBar(const std::string& label, int done, int total, double seconds);

}  // namespace retile::cli
