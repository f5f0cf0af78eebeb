// `retile eval`: every method through the same scenarios, scored against cached references, and
// a report an artist or a reviewer reads offline (eval::runReport): metrics.csv, summary.csv,
// charts (PNG and SVG), strips of frames with the overlays, and index.html tying them together.
// Here: the options, and the pictures, which take Qt.
#include <QApplication>

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>

#include "cli.h"
#include "cli11.h"
#include "eval_report.h"
#include "retile/eval.h"
#include "retile/log.h"

namespace retile::cli {

namespace {

// The report's host: scenes by the command line's names, the terminal, and the pictures, drawn
// with Qt (which the engine does not link) on the offscreen platform.
class CliReportHost : public eval::ReportHost {
 public:
  Result<ImportedScene> loadScene(const std::string& name) override { return cli::loadScene(name); }
  void progress(const std::string& what, int done, int total, double seconds) override { progressBar(what, done, total, seconds); }
  void out(const std::string& text) override { std::fputs(text.c_str(), stdout); }
  void err(const std::string& text) override { std::fputs(text.c_str(), stderr); }

  void keepStripFrame(std::size_t strip, std::size_t row, const FrameRecord& frame, int scale) override {
    std::vector<ui::StripRow>& rows = strips_[strip];
    if (rows.size() <= row) rows.resize(row + 1);
    rows[row].cells.push_back(ui::frameWithOverlays(frame, scale));
  }
  Result<bool> writeStrip(std::size_t strip, const std::filesystem::path& file, const std::vector<std::string>& captions,
                          const std::vector<std::string>& rows) override {
    std::vector<ui::StripRow> cells = std::move(strips_[strip]);
    strips_.erase(strip);
    cells.resize(rows.size());
    for (std::size_t i = 0; i < rows.size(); ++i) cells[i].label = QString::fromStdString(rows[i]);
    std::vector<QString> columns;
    for (const auto& c : captions) columns.push_back(QString::fromStdString(c));
    return ui::writeStrip(file, columns, cells);
  }
  Result<bool> writeLineChart(const std::filesystem::path& base, const std::string& title, const std::string& xTitle,
                              const std::string& yTitle, const std::vector<eval::ReportLine>& lines, bool logX) override {
    std::vector<ui::ChartLine> chart;
    for (const auto& l : lines) {
      ui::ChartLine c{QString::fromStdString(l.name), {}};
      for (const auto& [x, y] : l.points) c.points.emplace_back(x, y);
      chart.push_back(std::move(c));
    }
    return ui::writeLineChart(base, qt(title), qt(xTitle), qt(yTitle), chart, logX);
  }
  Result<bool> writePointChart(const std::filesystem::path& base, const std::string& title, const std::string& xTitle,
                               const std::string& yTitle, const std::vector<eval::ReportPoint>& points) override {
    std::vector<ui::ChartPoint> chart;
    for (const auto& p : points) chart.push_back({QString::fromStdString(p.label), {}, QPointF(p.x, p.y), p.reached});
    return ui::writePointChart(base, qt(title), qt(xTitle), qt(yTitle), chart);
  }

 private:
  static QString qt(const std::string& s) { return QString::fromStdString(s); }
  std::map<std::size_t, std::vector<ui::StripRow>> strips_;
};

// The charts and strips are drawn with Qt offscreen: no display is needed, and the viewport
// paints itself instead of asking for a Vulkan surface.
std::unique_ptr<QApplication> offscreenQt() {
  qputenv("QT_QPA_PLATFORM", "offscreen");
  qputenv("RETILE_VIEWPORT", "widget");
  if (qEnvironmentVariableIsEmpty("XDG_RUNTIME_DIR")) {  // Qt warns without one (CI, ssh, cron)
    std::error_code ec;
    const std::filesystem::path runtime = std::filesystem::temp_directory_path() / cat("retile-runtime-", ::getuid());
    std::filesystem::create_directories(runtime, ec);
    std::filesystem::permissions(runtime, std::filesystem::perms::owner_all, ec);
    qputenv("XDG_RUNTIME_DIR", QByteArray::fromStdString(runtime.string()));
  }
  static int qtArgc = 1;
  static char qtName[] = "retile";
  static char* qtArgv[] = {qtName, nullptr};
  // The offscreen platform says it cannot pass size hints each time a chart's view is shown:
  // nothing a user can act on.
  qInstallMessageHandler([](QtMsgType type, const QMessageLogContext&, const QString& message) {
    if (message.contains(QLatin1String("propagateSizeHints"))) return;
    std::fprintf(stderr, "%s: %s\n", type == QtWarningMsg ? "qt warning" : "qt", message.toLocal8Bit().constData());
  });
  return std::make_unique<QApplication>(qtArgc, qtArgv);
}

struct EvalOptions {
  std::vector<std::string> scenes{"default"};
  std::string outDir;
  bool quick = false, stability = false;
  std::optional<ImageSize> size;
  std::vector<std::string> methods, scenarios, scripts, cases;
  std::optional<int> referenceSpp, every, converge;
  std::optional<double> target;
};

int runEval(const EvalOptions& o) {
  eval::ReportRequest request;
  eval::Options& opt = request.options;
  opt = o.quick ? eval::Options::quick() : eval::Options{};
  if (o.size) opt.width = o.size->width, opt.height = o.size->height;
  if (o.referenceSpp) opt.referenceSpp = *o.referenceSpp;
  if (o.every) opt.every = *o.every;
  if (o.converge) opt.converge = *o.converge;
  if (o.target) opt.target = *o.target;
  request.methods = o.methods.empty() ? eval::defaultMethods() : o.methods;
  for (const auto& file : o.scripts) {
    auto s = loadScenario(file);
    if (!s) return std::fprintf(stderr, "error: %s\n", s.error().c_str()), 1;
    request.scripts.push_back(s.value());
  }
  request.scenes = o.scenes;
  request.scenarios = o.scenarios;
  request.out = o.outDir;
  CliReportHost host;
  if (o.stability) {
    eval::StabilityOptions so;
    if (o.quick) so.width = 96, so.height = 54, so.referenceSpp = 512, so.small = true;
    if (o.size) so.width = opt.width, so.height = opt.height;
    if (o.referenceSpp) so.referenceSpp = opt.referenceSpp;
    if (!o.methods.empty()) so.methods = request.methods;
    return eval::runStabilityReport(o.scenes, o.cases.empty() ? eval::stabilityCaseNames() : o.cases, so, o.outDir, host);
  }
  const std::unique_ptr<QApplication> app = offscreenQt();
  return eval::runReport(request, host);
}

}  // namespace

void addEval(CLI::App& app, int* status) {
  CLI::App* cmd = app.add_subcommand("eval",
                                     "Every method through the same scenarios, scored against cached references: a report in --out-dir "
                                     "(index.html, CSV, charts); with --stability, the stability suite");
  auto o = std::make_shared<EvalOptions>();
  const eval::Options full, quick = eval::Options::quick();
  const eval::StabilityOptions stable;
  auto join = [](const std::vector<std::string>& names) {
    std::string s;
    for (const auto& n : names) s += (s.empty() ? "" : ", ") + n;
    return s;
  };
  cmd->add_option("SCENE", o->scenes,
                  "scene files (glTF, OBJ, FBX, PLY, Tungsten scene.json, .retile) or 'default' "
                  "(default: default)")
      ->type_name("");
  cmd->add_option("--out-dir", o->outDir,
                  "where the report and the references go (made if missing; references "
                  "already there are reused)")
      ->required()
      ->type_name("DIR");
  cmd->add_flag("--quick", o->quick, "small images, short scenarios, lower references (what the tests run)");
  cmd->add_flag("--stability", o->stability, "run the stability suite (stability.csv, stability.html) instead of the scenarios");
  addSize(*cmd, &o->size, "image size",
          cat(full.width, "x", full.height, ", ", quick.width, "x", quick.height, " with --quick; --stability: ", stable.width, "x",
              stable.height));
  // Every list is checked item by item when it is read, so a typo fails before any rendering.
  auto checkEach = [](auto read) {
    return CLI::Validator(
        [read](std::string& item) {
          auto r = read(item);
          return r ? std::string() : r.error();
        },
        "");
  };
  std::string labels;
  for (const auto& n : methodNames()) labels += (labels.empty() ? "" : ", ") + n;
  cmd->add_option(
         "--methods", o->methods,
         "comma-separated methods, each of " + labels + " with +smooth, +denoise, +reuse (default: " + join(eval::defaultMethods()) + ")")
      ->type_name("LIST")
      ->delimiter(',')
      ->allow_extra_args(false)
      ->check(checkEach([](const std::string& label) { return eval::parseMethodLabel(label); }));
  cmd->add_option("--scenarios", o->scenarios,
                  "comma-separated built-in scenarios: " + join(eval::builtInScenarioNames()) +
                      " (default: all of them, none when --script is given)")
      ->type_name("LIST")
      ->delimiter(',')
      ->allow_extra_args(false)
      ->check(oneOf("scenario", eval::builtInScenarioNames()));
  cmd->add_option("--script", o->scripts, "a scenario script to play as well (repeat for more)")
      ->type_name("FILE")
      ->allow_extra_args(false);
  addInt(*cmd, "--reference-spp", &o->referenceSpp, 1, 1 << 20, "samples per pixel of the references",
         cat(full.referenceSpp, ", ", quick.referenceSpp, " with --quick"));
  addInt(*cmd, "--every", &o->every, 1, 100000, "while edits arrive, score frames 1, 10, K, 2K, ...",
         cat(full.every, ", ", quick.every, " with --quick"))
      ->type_name("K");
  addInt(*cmd, "--converge", &o->converge, 0, 1 << 20, "samples per pixel before the first edit",
         cat(full.converge, ", ", quick.converge, " with --quick"))
      ->type_name("SPP");
  addNumber(*cmd, "--target", &o->target, 1e-6, 10, "relative RMSE of the affected region that counts as reached",
            cat(full.target, ", ", quick.target, " with --quick"))
      ->type_name("REL");
  CLI::Option* stability = cmd->get_option("--stability");
  cmd->add_option("--cases", o->cases, "with --stability: comma-separated cases (default: all): " + join(eval::stabilityCaseNames()))
      ->type_name("LIST")
      ->delimiter(',')
      ->allow_extra_args(false)
      ->check(oneOf("stability case", eval::stabilityCaseNames()))
      ->needs(stability);
  cmd->callback([o, status] { *status = runEval(*o); });
}

}  // namespace retile::cli
