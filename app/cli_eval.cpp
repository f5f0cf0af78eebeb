// `retile eval`: every method through the same scenarios, scored against cached references, and
// a report an artist or a reviewer reads offline: metrics.csv, summary.csv, charts (PNG and SVG),
// strips of frames with the overlays, and index.html tying them together.
#include <QApplication>

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>

#include "cli.h"
#include "cli11.h"
#include "core/files.h"
#include "eval_report.h"
#include "retile/eval.h"
#include "retile/log.h"

namespace retile::cli {

namespace {

using Clock = std::chrono::steady_clock;

std::string html(const std::string& s) {
  std::string o;
  for (char c : s) {
    if (c == '<') o += "&lt;";
    else if (c == '>') o += "&gt;";
    else if (c == '&') o += "&amp;";
    else if (c == '"') o += "&quot;";
    else o += c;
  }
  return o;
}

std::string fixed(double v, int decimals) {
  if (std::isnan(v)) return "–";
  if (std::isinf(v)) return "∞";
  char b[32];
  std::snprintf(b, sizeof b, "%.*f", decimals, v);
  return b;
}

// A name safe in a file name: letters, digits, '-' and '_'.
std::string slug(const std::string& s) {
  std::string o;
  for (char c : s) o += std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' ? c : '_';
  return o;
}

struct ScenarioResult {
  std::string scene, sceneSlug;
  eval::Case scenario;
  std::size_t affected = 0, pixels = 0;
  std::vector<eval::Run> runs;
  std::vector<eval::Summary> summaries;
  std::vector<int> stripFrames;
  std::vector<ui::StripRow> strip;
  std::vector<std::string> charts;  // file bases, relative to the output directory
};

int runStability(const std::vector<std::string>& sceneNames, const std::vector<std::string>& cases, const eval::StabilityOptions& options,
                 const std::filesystem::path& out) {
  std::error_code ec;
  std::filesystem::create_directories(out, ec);
  if (ec) return std::fprintf(stderr, "error: cannot create %s: %s\n", out.string().c_str(), ec.message().c_str()), 1;
  eval::References refs(out / "references", options.referenceSpp);
  const auto start = Clock::now();
  std::string csv = "scene,case,method,figure,threshold,pass,detail,broken\n";
  std::string page =
      "<!doctype html>\n<html><head><meta charset=\"utf-8\"><title>Retile stability</title>\n"
      "<style>body{font:14px/1.45 sans-serif;margin:2em auto;max-width:1100px;color:#222}"
      "table{border-collapse:collapse;margin:1em 0}td,th{border:1px solid #ccc;padding:3px 7px}"
      "th{background:#f2f2f2}.fail{color:#b00;font-weight:bold}.pass{color:#070}</style></head><body>\n"
      "<h1>Retile stability suite</h1>\n";
  page += cat("<p>", options.width, "x", options.height, ", references of ", options.referenceSpp,
              " spp. A method passes a case when its figure is at most 1.5 times the global method's (a restart "
              "shows nothing stale) and no invariant broke (exact W x H samples every frame, finite pixels, no "
              "error).</p>\n");
  int broken = 0, failed = 0, total = 0;
  for (const auto& sceneName : sceneNames) {
    auto loaded = loadScene(sceneName);
    if (!loaded) return std::fprintf(stderr, "error: %s\n", loaded.error().c_str()), 1;
    for (const auto& c : cases) {
      const int index = static_cast<int>(&c - cases.data());
      auto result = eval::runStabilityCase(c, loaded->scene, options, refs, [&](const std::string& what) {
        progressBar(what, index, static_cast<int>(cases.size()), std::chrono::duration<double>(Clock::now() - start).count());
      });
      if (!result) {
        std::fprintf(stderr, "\n%s: %s: cannot run: %s\n", sceneName.c_str(), c.c_str(), result.error().c_str());
        csv += cat(sceneName, ",", c, ",,,,,,\"", result.error(), "\"\n");
        page += cat("<h2>", html(c), "</h2><p class=\"fail\">Cannot run: ", html(result.error()), "</p>\n");
        ++broken;
        continue;
      }
      page += cat("<h2>", html(sceneName), ": ", html(c), "</h2>\n<p>", html(result->description), " Affected pixels: ", result->affected,
                  ". Figure: ", html(result->figure),
                  ".</p>\n<table><tr><th>method</th><th>figure</th>"
                  "<th>threshold</th><th>result</th><th>also measured</th></tr>\n");
      std::printf("\n%s: %s (%s)\n", sceneName.c_str(), c.c_str(), result->figure.c_str());
      for (const auto& f : result->figures) {
        ++total;
        failed += !f.pass;
        broken += !f.broken.empty();
        const std::string verdict = !f.broken.empty() ? "BROKEN: " + f.broken : (f.pass ? "pass" : "fail");
        std::printf("  %-26s %9s  <= %9s  %s%s%s\n", f.method.c_str(), fixed(f.value, 4).c_str(), fixed(f.threshold, 4).c_str(),
                    verdict.c_str(), f.detail.empty() ? "" : "  ", f.detail.c_str());
        csv += cat(sceneName, ",", c, ",", f.method, ",", std::isnan(f.value) ? std::string() : fixed(f.value, 5), ",",
                   std::isnan(f.threshold) ? std::string() : fixed(f.threshold, 5), ",", f.pass ? 1 : 0, ",\"", f.detail, "\",\"", f.broken,
                   "\"\n");
        page += cat("<tr><td>", html(f.method), "</td><td>", fixed(f.value, 4), "</td><td>", fixed(f.threshold, 4), "</td><td class=\"",
                    f.pass ? "pass" : "fail", "\">", html(verdict), "</td><td>", html(f.detail), "</td></tr>\n");
      }
      page += "</table>\n";
    }
  }
  page += "</body></html>\n";
  if (auto w = writeFileAtomic(out / "stability.csv", csv); !w) return std::fprintf(stderr, "error: %s\n", w.error().c_str()), 1;
  if (auto w = writeFileAtomic(out / "stability.html", page); !w) return std::fprintf(stderr, "error: %s\n", w.error().c_str()), 1;
  std::printf("\n%d of %d figures pass; %d broke an invariant. Wrote %s in %.0f s\n", total - failed, total, broken,
              (out / "stability.html").string().c_str(), std::chrono::duration<double>(Clock::now() - start).count());
  // A method failing a case is a finding, reported above; a broken invariant is a defect.
  return broken > 0 ? 1 : 0;
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
  eval::Options opt = o.quick ? eval::Options::quick() : eval::Options{};
  if (o.size) opt.width = o.size->width, opt.height = o.size->height;
  if (o.referenceSpp) opt.referenceSpp = *o.referenceSpp;
  if (o.every) opt.every = *o.every;
  if (o.converge) opt.converge = *o.converge;
  if (o.target) opt.target = *o.target;
  const std::vector<std::string> methodLabels = o.methods.empty() ? eval::defaultMethods() : o.methods;
  std::vector<MethodSettings> methods;
  for (const auto& label : methodLabels) methods.push_back(eval::parseMethodLabel(label).value());  // checked by the option
  const std::vector<std::string>& scenarioNames = o.scenarios;
  std::vector<Scenario> scripts;
  for (const auto& file : o.scripts) {
    auto s = loadScenario(file);
    if (!s) return std::fprintf(stderr, "error: %s\n", s.error().c_str()), 1;
    scripts.push_back(s.value());
  }
  // Only scripts were asked for: no built-in scenario unless named.
  const bool builtIns = scripts.empty() || !scenarioNames.empty();
  const std::vector<std::string>& sceneNames = o.scenes;
  if (o.stability) {
    eval::StabilityOptions so;
    if (o.quick) so.width = 96, so.height = 54, so.referenceSpp = 512, so.small = true;
    if (o.size) so.width = opt.width, so.height = opt.height;
    if (o.referenceSpp) so.referenceSpp = opt.referenceSpp;
    if (!o.methods.empty()) so.methods = methodLabels;
    return runStability(sceneNames, o.cases.empty() ? eval::stabilityCaseNames() : o.cases, so, o.outDir);
  }

  const std::filesystem::path out = o.outDir;
  std::error_code ec;
  std::filesystem::create_directories(out / "charts", ec);
  std::filesystem::create_directories(out / "strips", ec);
  if (ec) return std::fprintf(stderr, "error: cannot create %s: %s\n", out.string().c_str(), ec.message().c_str()), 1;

  // The charts and strips are drawn with Qt offscreen: no display is needed, and the viewport
  // paints itself instead of asking for a Vulkan surface.
  qputenv("QT_QPA_PLATFORM", "offscreen");
  qputenv("RETILE_VIEWPORT", "widget");
  if (qEnvironmentVariableIsEmpty("XDG_RUNTIME_DIR")) {  // Qt warns without one (CI, ssh, cron)
    const std::filesystem::path runtime = std::filesystem::temp_directory_path() / cat("retile-runtime-", ::getuid());
    std::filesystem::create_directories(runtime, ec);
    std::filesystem::permissions(runtime, std::filesystem::perms::owner_all, ec);
    qputenv("XDG_RUNTIME_DIR", QByteArray::fromStdString(runtime.string()));
  }
  int qtArgc = 1;
  char qtName[] = "retile";
  char* qtArgv[] = {qtName, nullptr};
  // The offscreen platform says it cannot pass size hints each time a chart's view is shown:
  // nothing a user can act on.
  qInstallMessageHandler([](QtMsgType type, const QMessageLogContext&, const QString& message) {
    if (message.contains(QLatin1String("propagateSizeHints"))) return;
    std::fprintf(stderr, "%s: %s\n", type == QtWarningMsg ? "qt warning" : "qt", message.toLocal8Bit().constData());
  });
  QApplication app(qtArgc, qtArgv);

  eval::References refs(out / "references", opt.referenceSpp);
  std::ofstream metrics(out / "metrics.csv");
  metrics << eval::metricsCsvHeader();
  std::vector<ScenarioResult> results;
  std::vector<std::string> notes;
  const auto start = Clock::now();
  auto seconds = [&] { return std::chrono::duration<double>(Clock::now() - start).count(); };

  // Everything is planned first, so the progress bar knows the whole run's frames.
  struct Job {
    std::string sceneName;
    eval::Case scenario;
    eval::Plan plan;
  };
  std::vector<Job> jobs;
  std::vector<std::pair<std::string, eval::SceneModel>> models;
  for (const auto& sceneName : sceneNames) {
    auto loaded = loadScene(sceneName);
    if (!loaded) return std::fprintf(stderr, "error: %s\n", loaded.error().c_str()), 1;
    for (const auto& w : loaded->warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
    Scene scene = loaded->scene;
    scene.settings.width = opt.width;
    scene.settings.height = opt.height;
    models.emplace_back(sceneName, eval::modelOf(scene));
    std::vector<std::string> skipped;
    std::vector<eval::Case> cases;
    if (builtIns) cases = eval::builtInScenarios(scene, opt, scenarioNames, &skipped);
    for (const auto& s : skipped) notes.push_back(cat(sceneName, ": scenario ", s));
    for (const Scenario& s : scripts) cases.push_back({s.name, "A script: " + s.name, s});
    for (auto& c : cases) {
      auto plan = eval::planScenario(c.script, scene, opt.every);
      if (!plan) {
        notes.push_back(cat(sceneName, ": scenario ", c.name, " left out: ", plan.error()));
        std::fprintf(stderr, "warning: %s: %s: %s\n", sceneName.c_str(), c.name.c_str(), plan.error().c_str());
        continue;
      }
      jobs.push_back({sceneName, c, std::move(plan.value())});
    }
  }
  if (jobs.empty()) return std::fprintf(stderr, "error: no scenario to play\n"), 1;
  for (const auto& n : notes) std::fprintf(stderr, "note: %s\n", n.c_str());

  int totalFrames = 0, doneFrames = 0;
  for (const Job& j : jobs) totalFrames += static_cast<int>(methods.size()) * (j.plan.converge + static_cast<int>(j.plan.frames.size()));

  for (Job& job : jobs) {
    ScenarioResult res;
    res.scene = job.sceneName;
    res.sceneSlug = slug(std::filesystem::path(job.sceneName).parent_path().filename().string().empty()
                             ? std::filesystem::path(job.sceneName).stem().string()
                             : std::filesystem::path(job.sceneName).parent_path().filename().string() + "-" +
                                   std::filesystem::path(job.sceneName).stem().string());
    if (job.sceneName == "default") res.sceneSlug = "default";
    res.scenario = job.scenario;
    const std::string label = cat(res.sceneSlug, " ", job.scenario.name);
    const auto refStart = Clock::now();
    auto targets = eval::prepareTargets(job.plan, refs, [&](int done, int total) {
      progressBar(label + " references", done, total, std::chrono::duration<double>(Clock::now() - refStart).count());
    });
    if (!targets) return std::fprintf(stderr, "\nerror: %s\n", targets.error().c_str()), 1;
    res.affected = targets->affectedCount;
    res.pixels = static_cast<std::size_t>(opt.width) * static_cast<std::size_t>(opt.height);
    const int frames = static_cast<int>(job.plan.frames.size());
    for (int f : {1, 10, job.plan.lastEditFrame + 10, frames})
      if (f >= 1 && f <= frames && std::find(res.stripFrames.begin(), res.stripFrames.end(), f) == res.stripFrames.end())
        res.stripFrames.push_back(f);
    std::sort(res.stripFrames.begin(), res.stripFrames.end());
    const int scale = std::max(1, 240 / std::max(opt.width, 1));
    for (const MethodSettings& m : methods) {
      ui::StripRow row;
      row.label = QString::fromStdString(methodLabel(m));
      doneFrames += job.plan.converge;
      auto run = eval::runMethod(job.plan, targets.value(), m, [&](const FrameRecord& rec, const eval::FrameScore& s) {
        progressBar("eval", ++doneFrames, totalFrames, seconds());
        if (std::find(res.stripFrames.begin(), res.stripFrames.end(), s.frame) != res.stripFrames.end())
          row.cells.push_back(ui::frameWithOverlays(rec, scale));
        return true;
      });
      if (!run) return std::fprintf(stderr, "\nerror: %s %s: %s\n", label.c_str(), methodLabel(m).c_str(), run.error().c_str()), 1;
      run->scene = res.sceneSlug;
      run->scenario = job.scenario.name;
      for (const auto& f : run->frames) metrics << eval::metricsCsvRow(run.value(), f);
      metrics.flush();
      if (!run->exactBudget) notes.push_back(cat(label, " ", run->method, ": a frame did not trace exactly W x H samples"));
      res.summaries.push_back(eval::summarize(run.value(), opt.target));
      res.runs.push_back(std::move(run.value()));
      res.strip.push_back(std::move(row));
    }
    results.push_back(std::move(res));
  }
  metrics.close();
  std::fprintf(stderr, "references: %d rendered, %d reused from %s\n", refs.rendered(), refs.reused(),
               (out / "references").string().c_str());

  // summary.csv and the table on the terminal.
  std::string summaryCsv = eval::summaryCsvHeader();
  for (const auto& r : results)
    for (const auto& s : r.summaries) summaryCsv += eval::summaryCsvRow(s);
  if (auto w = writeFileAtomic(out / "summary.csv", summaryCsv); !w) return std::fprintf(stderr, "error: %s\n", w.error().c_str()), 1;

  // Charts and strips.
  int chartsWritten = 0;
  for (auto& r : results) {
    const std::string base = cat(r.sceneSlug, "-", slug(r.scenario.name));
    std::vector<ui::ChartLine> whole, affected;
    std::vector<ui::ChartPoint> tradeoff;
    for (std::size_t i = 0; i < r.runs.size(); ++i) {
      const eval::Run& run = r.runs[i];
      ui::ChartLine a{QString::fromStdString(run.method), {}}, b{QString::fromStdString(run.method), {}};
      for (const auto& f : run.frames) {
        if (!f.scored()) continue;
        a.points.emplace_back(f.ms, f.psnr);
        b.points.emplace_back(f.ms, r.affected > 0 ? f.psnrAffected : f.psnr);
      }
      whole.push_back(std::move(a));
      affected.push_back(std::move(b));
      const eval::Summary& s = r.summaries[i];
      const double at10 = r.affected > 0 ? s.psnrAffectedAt[1] : s.psnrAt[1];
      const bool reached = s.framesToTarget >= 0;
      const double x = reached ? s.msToTarget : (run.frames.empty() ? NAN : run.frames.back().ms);
      // Not reached: drawn in the chart's "not reached" band; the run's length only sizes the time
      // axis when no method reached the target.
      tradeoff.push_back({QString::fromStdString(run.method), {}, QPointF(x, at10), reached});
    }
    const QString title = QString::fromStdString(cat(r.scene, ": ", r.scenario.name));
    const QString timeAxis = QStringLiteral("wall clock since the first edit (ms)");
    struct Chart {
      std::string name;
      Result<bool> written;
    };
    std::vector<Chart> made;
    made.push_back({base + "-psnr", ui::writeLineChart(out / "charts" / (base + "-psnr"), title + " — PSNR, whole image", timeAxis,
                                                       "PSNR (dB)", whole, true)});
    made.push_back(
        {base + "-affected", ui::writeLineChart(out / "charts" / (base + "-affected"),
                                                title + (r.affected > 0 ? " — PSNR, affected region" : " — PSNR (nothing changed)"),
                                                timeAxis, "PSNR (dB)", affected, true)});
    made.push_back({base + "-tradeoff", ui::writePointChart(out / "charts" / (base + "-tradeoff"), title + " — speed against accuracy",
                                                            QString::fromStdString(cat("time to ", opt.target * 100,
                                                                                       " % relative RMSE in the affected region (ms)")),
                                                            "PSNR of the affected region at frame 10 (dB)", tradeoff)});
    for (auto& c : made) {
      if (!c.written) return std::fprintf(stderr, "error: %s\n", c.written.error().c_str()), 1;
      r.charts.push_back(c.name);
      ++chartsWritten;
    }
    std::vector<QString> captions;
    for (int f : r.stripFrames) captions.push_back(QStringLiteral("frame %1").arg(f));
    auto strip = ui::writeStrip(out / "strips" / (base + ".png"), captions, r.strip);
    if (!strip) return std::fprintf(stderr, "error: %s\n", strip.error().c_str()), 1;
  }

  // index.html: readable offline, everything relative.
  std::string page =
      "<!doctype html>\n<html><head><meta charset=\"utf-8\"><title>Retile evaluation</title>\n"
      "<style>body{font:14px/1.45 sans-serif;margin:2em auto;max-width:1200px;color:#222}"
      "table{border-collapse:collapse;margin:1em 0}td,th{border:1px solid #ccc;padding:3px 7px;text-align:right}"
      "th{background:#f2f2f2}td:first-child,th:first-child{text-align:left}img{max-width:100%}"
      ".note{color:#555}</style></head><body>\n<h1>Retile evaluation</h1>\n";
  page += cat("<p>", opt.width, "x", opt.height, ", every method on the same budget (", opt.width, "x", opt.height,
              " samples a frame), references of ", opt.referenceSpp, " spp. Scored: frame 1, every ", opt.every,
              "th frame while edits arrive, every frame at rest. PSNR, SSIM and PSNR-HVS-M compare display-referred "
              "images (sRGB view, clamped); the <em>affected region</em> is where the scenario's references differ from "
              "the start beyond their noise. Time to target: from frame 1 until the affected region's relative RMSE "
              "(linear luminance, 4x4 blocks) stays at or below ",
              opt.target * 100, " %.</p>\n");
  page += "<p>Data: <a href=\"metrics.csv\">metrics.csv</a> (every frame), <a href=\"summary.csv\">summary.csv</a>.</p>\n";
  for (const auto& n : notes) page += "<p class=\"note\">" + html(n) + "</p>\n";
  page +=
      "<h2>What each scene costs the renderer</h2>\n<table><tr><th>scene</th><th>triangles</th><th>device memory "
      "(BVH included)</th><th>bytes per triangle</th><th>trace kernel compiled with</th></tr>\n";
  for (const auto& [name, m] : models) {
    std::string features;
    for (const auto& f : m.kernelFeatures) features += (features.empty() ? "" : ", ") + f;
    page += cat("<tr><td>", html(name), "</td><td>", m.triangles, "</td><td>", fixed(static_cast<double>(m.deviceBytes) / (1 << 20), 2),
                " MiB</td><td>", fixed(m.bytesPerTriangle, 1), "</td><td>", html(features), "</td></tr>\n");
    std::printf("%s: %llu triangles, %.2f MiB on the device (%.1f bytes per triangle), kernel: %s\n", name.c_str(),
                static_cast<unsigned long long>(m.triangles), static_cast<double>(m.deviceBytes) / (1 << 20), m.bytesPerTriangle,
                features.c_str());
  }
  page += "</table>\n";
  for (const auto& r : results) {
    const std::string base = cat(r.sceneSlug, "-", slug(r.scenario.name));
    page += cat("<h2>", html(r.scene), ": ", html(r.scenario.name), "</h2>\n<p>", html(r.scenario.description),
                " Affected region: ", r.affected, " of ", r.pixels, " pixels.</p>\n");
    page += "<table><tr><th>method</th>";
    for (int f : eval::Summary::kAt) page += cat("<th>PSNR @", f, "</th>");
    for (int f : eval::Summary::kAt) page += cat("<th>affected @", f, "</th>");
    page += "<th>frames to target</th><th>ms to target</th></tr>\n";
    for (const auto& s : r.summaries) {
      page += "<tr><td>" + html(s.method) + "</td>";
      for (double v : s.psnrAt) page += "<td>" + fixed(v, 2) + "</td>";
      for (double v : s.psnrAffectedAt) page += "<td>" + fixed(v, 2) + "</td>";
      page += s.framesToTarget >= 0 ? cat("<td>", s.framesToTarget, "</td><td>", fixed(s.msToTarget, 0), "</td>")
                                    : std::string("<td>not reached</td><td>–</td>");
      page += "</tr>\n";
    }
    page += "</table>\n";
    for (const auto& c : r.charts)
      page += cat("<p><a href=\"charts/", c, ".svg\"><img src=\"charts/", c, ".png\" alt=\"", c, "\"></a></p>\n");
    page += cat("<p>Frames ");
    for (std::size_t i = 0; i < r.stripFrames.size(); ++i) page += cat(i ? ", " : "", r.stripFrames[i]);
    page +=
        cat(" with the overlays: tiles traced that frame outlined, queue priority as a heat map, the point of "
            "change and focus points marked, denoised regions framed.</p>\n<p><img src=\"strips/",
            base, ".png\" alt=\"strip\"></p>\n");
  }
  page += "</body></html>\n";
  if (auto w = writeFileAtomic(out / "index.html", page); !w) return std::fprintf(stderr, "error: %s\n", w.error().c_str()), 1;

  std::printf("%-10s %-10s %-22s %9s %9s %9s %9s %9s %9s %9s\n", "scene", "scenario", "method", "psnr@1", "psnr@10", "psnr@100", "aff@1",
              "aff@10", "aff@100", "target ms");
  for (const auto& r : results)
    for (const auto& s : r.summaries)
      std::printf("%-10s %-10s %-22s %9s %9s %9s %9s %9s %9s %9s\n", s.scene.c_str(), s.scenario.c_str(), s.method.c_str(),
                  fixed(s.psnrAt[0], 2).c_str(), fixed(s.psnrAt[1], 2).c_str(), fixed(s.psnrAt[2], 2).c_str(),
                  fixed(s.psnrAffectedAt[0], 2).c_str(), fixed(s.psnrAffectedAt[1], 2).c_str(), fixed(s.psnrAffectedAt[2], 2).c_str(),
                  s.framesToTarget >= 0 ? fixed(s.msToTarget, 0).c_str() : "not");
  std::printf("wrote %s (%d charts, %zu strips) in %.0f s\n", (out / "index.html").string().c_str(), chartsWritten, results.size(),
              seconds());
  return 0;
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
