// The command line: `retile render`, `retile edit`, `retile eval`, `retile compare`, `retile bench`, `retile import`. Runs on the main thread.
#pragma once

#include <string>
#include <vector>

#include "retile/error.h"
#include "retile/io.h"

namespace retile::cli {

// Parsed "--name value" options and positional arguments; unknown options are errors.
struct Args {
  std::vector<std::string> positional;
  std::vector<std::pair<std::string, std::string>> options;
  bool has(const std::string& name) const;
  std::string get(const std::string& name, const std::string& fallback = "") const;
};

Result<Args> parseArgs(const std::vector<std::string>& argv, const std::vector<std::string>& known,
                       const std::vector<std::string>& flags = {});
Result<int> parseInt(const std::string& option, const std::string& text, int lo, int hi);
Result<double> parseNumber(const std::string& option, const std::string& text, double lo, double hi);
Result<bool> parseSize(const std::string& text, int* width, int* height);

// "default" is the built-in scene; anything else a file any importer reads.
Result<ImportedScene> loadScene(const std::string& name);

// Prints the renderer's warnings about a scene, leaving out files the import already reported.
void printRenderWarnings(const std::vector<std::string>& renderWarnings, const std::vector<std::string>& importWarnings);
// A one-line progress bar on stderr, redrawn in place (a line per tenth when not a terminal).
void progressBar(const std::string& label, int done, int total, double seconds);

int runRender(const std::vector<std::string>& args);
int runBench(const std::vector<std::string>& args);
int runImport(const std::vector<std::string>& args);
int runEdit(const std::vector<std::string>& args);
int runEval(const std::vector<std::string>& args);
int runCompare(const std::vector<std::string>& args);
// The Qt editor on `file` ("" or "default": the built-in scene). Needs a display.
int runEditor(int argc, char** argv, const std::string& file);
bool isCommand(const std::string& word);

}  // namespace retile::cli
