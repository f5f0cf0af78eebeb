// The reports of `retile eval` (retile/eval.h): the scenarios' metrics.csv, summary.csv, charts,
// strips and index.html, and the stability suite's stability.csv and stability.html.
#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <fstream>

#include "core/files.h"
#include "retile/eval.h"
#include "retile/log.h"

namespace retile::eval {

namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

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

// printf's formatting, for the lines written to the terminal.
[[gnu::format(printf, 1, 2)]] std::string formatted(const char* format, ...) {
  std::va_list args, again;
  va_start(args, format);
  va_copy(again, args);
  const int n = std::vsnprintf(nullptr, 0, format, args);
  va_end(args);
  std::string s(static_cast<std::size_t>(std::max(n, 0)) + 1, '\0');
  std::vsnprintf(s.data(), s.size(), format, again);
  va_end(again);
  s.resize(static_cast<std::size_t>(std::max(n, 0)));
  return s;
}

// A name safe in a file name: letters, digits, '-' and '_'.
std::string slug(const std::string& s) {
  std::string o;
  for (char c : s) o += std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' ? c : '_';
  return o;
}

// A scene's name in the report's file names: its folder and file name ("living-room-scene").
std::string sceneSlug(const std::string& sceneName) {
  if (sceneName == "default") return "default";
  const std::filesystem::path p(sceneName);
  const std::string folder = p.parent_path().filename().string();
  return slug(folder.empty() ? p.stem().string() : folder + "-" + p.stem().string());
}

// Prints an error on the host; the command's exit status.
int failed(ReportHost& host, const std::string& line) {
  host.err(line);
  return 1;
}

// ---- The scenarios' report ----

// A scenario of a scene, planned.
struct Job {
  std::string sceneName;
  Case scenario;
  Plan plan;
};

struct Planned {
  std::vector<Job> jobs;
  std::vector<std::pair<std::string, SceneModel>> models;
  std::vector<std::string> notes;
};

struct ScenarioResult {
  std::string scene, sceneSlug;
  Case scenario;
  std::size_t affected = 0, pixels = 0;
  std::vector<Run> runs;
  std::vector<Summary> summaries;
  std::vector<int> stripFrames;
  std::vector<std::string> charts;  // file bases, relative to the output directory
  std::string base() const { return cat(sceneSlug, "-", slug(scenario.name)); }
};

// Every scenario of every scene planned first, so that the progress bar knows the whole run's
// frames. A scene that does not load fails the report; a scenario that cannot be planned is left
// out with a note.
Result<Planned> planJobs(const ReportRequest& request, ReportHost& host) {
  const Options& opt = request.options;
  // Only scripts were asked for: no built-in scenario unless named.
  const bool builtIns = request.scripts.empty() || !request.scenarios.empty();
  Planned p;
  for (const auto& sceneName : request.scenes) {
    auto loaded = host.loadScene(sceneName);
    if (!loaded) return Result<Planned>::failure(loaded.error());
    for (const auto& w : loaded->warnings) host.err(cat("warning: ", w, "\n"));
    Scene scene = loaded->scene;
    scene.settings.width = opt.width;
    scene.settings.height = opt.height;
    p.models.emplace_back(sceneName, modelOf(scene));
    std::vector<std::string> skipped;
    std::vector<Case> cases;
    if (builtIns) cases = builtInScenarios(scene, opt, request.scenarios, &skipped);
    for (const auto& s : skipped) p.notes.push_back(cat(sceneName, ": scenario ", s));
    for (const Scenario& s : request.scripts) cases.push_back({s.name, "A script: " + s.name, s});
    for (auto& c : cases) {
      auto plan = planScenario(c.script, scene, opt.every);
      if (!plan) {
        p.notes.push_back(cat(sceneName, ": scenario ", c.name, " left out: ", plan.error()));
        host.err(cat("warning: ", sceneName, ": ", c.name, ": ", plan.error(), "\n"));
        continue;
      }
      p.jobs.push_back({sceneName, c, std::move(plan.value())});
    }
  }
  if (p.jobs.empty()) return Result<Planned>::failure("no scenario to play");
  return p;
}

// Plays the planned scenarios under each method, writing metrics.csv as each run ends; the
// progress bar's time counts from `start`.
class Player {
 public:
  Player(const ReportRequest& request, ReportHost& host, References& refs, Clock::time_point start)
      : request_(request), host_(host), refs_(refs), metrics_(request.out / "metrics.csv"), start_(start) {
    for (const auto& label : request.methods) methods_.push_back(parseMethodLabel(label).value());
    metrics_ << metricsCsvHeader();
  }

  // Adds a note for each run that broke the budget.
  Result<std::vector<ScenarioResult>> playAll(Planned& planned) {
    for (const Job& j : planned.jobs)
      totalFrames_ += static_cast<int>(methods_.size()) * (j.plan.converge + static_cast<int>(j.plan.frames.size()));
    std::vector<ScenarioResult> results;
    for (Job& job : planned.jobs) {
      auto r = play(job, results.size(), planned.notes);
      if (!r) return Result<std::vector<ScenarioResult>>::failure(r.error());
      results.push_back(std::move(r.value()));
    }
    metrics_.close();
    return results;
  }

 private:
  // One scenario: its references, then every method, strip `strip` keeping the frames it shows.
  Result<ScenarioResult> play(Job& job, std::size_t strip, std::vector<std::string>& notes) {
    const Options& opt = request_.options;
    ScenarioResult res;
    res.scene = job.sceneName;
    res.sceneSlug = sceneSlug(job.sceneName);
    res.scenario = job.scenario;
    const std::string label = cat(res.sceneSlug, " ", job.scenario.name);
    const auto refStart = Clock::now();
    auto targets = prepareTargets(job.plan, refs_,
                                  [&](int done, int total) { host_.progress(label + " references", done, total, secondsSince(refStart)); });
    if (!targets) return Result<ScenarioResult>::failure(targets.error());
    res.affected = targets->affectedCount;
    res.pixels = static_cast<std::size_t>(opt.width) * static_cast<std::size_t>(opt.height);
    const int frames = static_cast<int>(job.plan.frames.size());
    for (int f : {1, 10, job.plan.lastEditFrame + 10, frames})
      if (f >= 1 && f <= frames && std::find(res.stripFrames.begin(), res.stripFrames.end(), f) == res.stripFrames.end())
        res.stripFrames.push_back(f);
    std::sort(res.stripFrames.begin(), res.stripFrames.end());
    for (std::size_t row = 0; row < methods_.size(); ++row) {
      const MethodSettings& m = methods_[row];
      doneFrames_ += job.plan.converge;
      auto run = runMethod(job.plan, targets.value(), m, [&](const FrameRecord& rec, const FrameScore& s) {
        host_.progress("eval", ++doneFrames_, totalFrames_, secondsSince(start_));
        if (std::find(res.stripFrames.begin(), res.stripFrames.end(), s.frame) != res.stripFrames.end())
          host_.keepStripFrame(strip, row, rec, std::max(1, 240 / std::max(opt.width, 1)));
        return true;
      });
      if (!run) return Result<ScenarioResult>::failure(cat(label, " ", methodLabel(m), ": ", run.error()));
      run->scene = res.sceneSlug;
      run->scenario = job.scenario.name;
      for (const auto& f : run->frames) metrics_ << metricsCsvRow(run.value(), f);
      metrics_.flush();
      if (!run->exactBudget) notes.push_back(cat(label, " ", run->method, ": a frame did not trace exactly W x H samples"));
      res.summaries.push_back(summarize(run.value(), opt.target));
      res.runs.push_back(std::move(run.value()));
    }
    return res;
  }

  const ReportRequest& request_;
  ReportHost& host_;
  References& refs_;
  std::ofstream metrics_;
  const Clock::time_point start_;
  std::vector<MethodSettings> methods_;
  int totalFrames_ = 0, doneFrames_ = 0;
};

Result<bool> writeSummaryCsv(const std::vector<ScenarioResult>& results, const std::filesystem::path& out) {
  std::string csv = summaryCsvHeader();
  for (const auto& r : results)
    for (const auto& s : r.summaries) csv += summaryCsvRow(s);
  return writeFileAtomic(out / "summary.csv", csv);
}

// A scenario's charts: PSNR against time, of the whole image and of the affected region, and
// speed against accuracy. Adds their names to r.charts.
Result<bool> writeCharts(ScenarioResult& r, double target, const std::filesystem::path& out, ReportHost& host) {
  std::vector<ReportLine> whole, affected;
  std::vector<ReportPoint> tradeoff;
  for (std::size_t i = 0; i < r.runs.size(); ++i) {
    const Run& run = r.runs[i];
    ReportLine a{run.method, {}}, b{run.method, {}};
    for (const auto& f : run.frames) {
      if (!f.scored()) continue;
      a.points.emplace_back(f.ms, f.psnr);
      b.points.emplace_back(f.ms, r.affected > 0 ? f.psnrAffected : f.psnr);
    }
    whole.push_back(std::move(a));
    affected.push_back(std::move(b));
    const Summary& s = r.summaries[i];
    const double at10 = r.affected > 0 ? s.psnrAffectedAt[1] : s.psnrAt[1];
    const bool reached = s.framesToTarget >= 0;
    const double x = reached ? s.msToTarget : (run.frames.empty() ? NAN : run.frames.back().ms);
    // Not reached: drawn in the chart's "not reached" band; the run's length only sizes the time
    // axis when no method reached the target.
    tradeoff.push_back({run.method, x, at10, reached});
  }
  const std::string base = r.base();
  const std::filesystem::path charts = out / "charts";
  const std::string title = cat(r.scene, ": ", r.scenario.name);
  const std::string timeAxis = "wall clock since the first edit (ms)";
  struct Chart {
    std::string name;
    Result<bool> written;
  };
  std::vector<Chart> made;
  made.push_back(
      {base + "-psnr", host.writeLineChart(charts / (base + "-psnr"), title + " — PSNR, whole image", timeAxis, "PSNR (dB)", whole, true)});
  made.push_back(
      {base + "-affected", host.writeLineChart(charts / (base + "-affected"),
                                               title + (r.affected > 0 ? " — PSNR, affected region" : " — PSNR (nothing changed)"),
                                               timeAxis, "PSNR (dB)", affected, true)});
  made.push_back({base + "-tradeoff", host.writePointChart(charts / (base + "-tradeoff"), title + " — speed against accuracy",
                                                           cat("time to ", target * 100, " % relative RMSE in the affected region (ms)"),
                                                           "PSNR of the affected region at frame 10 (dB)", tradeoff)});
  for (auto& c : made) {
    if (!c.written) return c.written;
    r.charts.push_back(c.name);
  }
  return true;
}

// index.html's opening: what was measured and how, the notes, and what each scene costs the
// renderer (also on host.out).
std::string indexHead(const Options& opt, const Planned& planned, ReportHost& host) {
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
  for (const auto& n : planned.notes) page += "<p class=\"note\">" + html(n) + "</p>\n";
  page +=
      "<h2>What each scene costs the renderer</h2>\n<table><tr><th>scene</th><th>triangles</th><th>device memory "
      "(BVH included)</th><th>bytes per triangle</th><th>trace kernel compiled with</th></tr>\n";
  for (const auto& [name, m] : planned.models) {
    std::string features;
    for (const auto& f : m.kernelFeatures) features += (features.empty() ? "" : ", ") + f;
    page += cat("<tr><td>", html(name), "</td><td>", m.triangles, "</td><td>", fixed(static_cast<double>(m.deviceBytes) / (1 << 20), 2),
                " MiB</td><td>", fixed(m.bytesPerTriangle, 1), "</td><td>", html(features), "</td></tr>\n");
    host.out(formatted("%s: %llu triangles, %.2f MiB on the device (%.1f bytes per triangle), kernel: %s\n", name.c_str(),
                       static_cast<unsigned long long>(m.triangles), static_cast<double>(m.deviceBytes) / (1 << 20), m.bytesPerTriangle,
                       features.c_str()));
  }
  page += "</table>\n";
  return page;
}

// A scenario's section of index.html: its summary table, charts and strip.
std::string indexSection(const ScenarioResult& r) {
  std::string page = cat("<h2>", html(r.scene), ": ", html(r.scenario.name), "</h2>\n<p>", html(r.scenario.description),
                         " Affected region: ", r.affected, " of ", r.pixels, " pixels.</p>\n");
  page += "<table><tr><th>method</th>";
  for (int f : Summary::kAt) page += cat("<th>PSNR @", f, "</th>");
  for (int f : Summary::kAt) page += cat("<th>affected @", f, "</th>");
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
          r.base(), ".png\" alt=\"strip\"></p>\n");
  return page;
}

// The summary as a table for the terminal.
std::string summaryTable(const std::vector<ScenarioResult>& results) {
  std::string t = formatted("%-10s %-10s %-22s %9s %9s %9s %9s %9s %9s %9s\n", "scene", "scenario", "method", "psnr@1", "psnr@10",
                            "psnr@100", "aff@1", "aff@10", "aff@100", "target ms");
  for (const auto& r : results)
    for (const auto& s : r.summaries)
      t += formatted("%-10s %-10s %-22s %9s %9s %9s %9s %9s %9s %9s\n", s.scene.c_str(), s.scenario.c_str(), s.method.c_str(),
                     fixed(s.psnrAt[0], 2).c_str(), fixed(s.psnrAt[1], 2).c_str(), fixed(s.psnrAt[2], 2).c_str(),
                     fixed(s.psnrAffectedAt[0], 2).c_str(), fixed(s.psnrAffectedAt[1], 2).c_str(), fixed(s.psnrAffectedAt[2], 2).c_str(),
                     s.framesToTarget >= 0 ? fixed(s.msToTarget, 0).c_str() : "not");
  return t;
}

// Charts, strips and index.html (readable offline, everything relative), once every scenario
// was played; the number of charts written.
Result<int> writePictures(std::vector<ScenarioResult>& results, double target, const std::filesystem::path& out, ReportHost& host) {
  int charts = 0;
  for (std::size_t i = 0; i < results.size(); ++i) {
    ScenarioResult& r = results[i];
    if (auto w = writeCharts(r, target, out, host); !w) return Result<int>::failure(w.error());
    charts += static_cast<int>(r.charts.size());
    std::vector<std::string> captions, rows;
    for (int f : r.stripFrames) captions.push_back(cat("frame ", f));
    for (const Run& run : r.runs) rows.push_back(run.method);
    if (auto w = host.writeStrip(i, out / "strips" / (r.base() + ".png"), captions, rows); !w) return Result<int>::failure(w.error());
  }
  return charts;
}

// ---- The stability suite's report ----

struct StabilityReport {
  std::string csv = "scene,case,method,figure,threshold,pass,detail,broken\n";
  std::string page;
  int broken = 0, failed = 0, total = 0;

  explicit StabilityReport(const StabilityOptions& options) {
    page =
        "<!doctype html>\n<html><head><meta charset=\"utf-8\"><title>Retile stability</title>\n"
        "<style>body{font:14px/1.45 sans-serif;margin:2em auto;max-width:1100px;color:#222}"
        "table{border-collapse:collapse;margin:1em 0}td,th{border:1px solid #ccc;padding:3px 7px}"
        "th{background:#f2f2f2}.fail{color:#b00;font-weight:bold}.pass{color:#070}</style></head><body>\n"
        "<h1>Retile stability suite</h1>\n";
    page += cat("<p>", options.width, "x", options.height, ", references of ", options.referenceSpp,
                " spp. A method passes a case when its figure is at most 1.5 times the global method's (a restart "
                "shows nothing stale) and no invariant broke (exact W x H samples every frame, finite pixels, no "
                "error).</p>\n");
  }

  void cannotRun(const std::string& sceneName, const std::string& c, const std::string& error, ReportHost& host) {
    host.err(cat("\n", sceneName, ": ", c, ": cannot run: ", error, "\n"));
    csv += cat(sceneName, ",", c, ",,,,,,\"", error, "\"\n");
    page += cat("<h2>", html(c), "</h2><p class=\"fail\">Cannot run: ", html(error), "</p>\n");
    ++broken;
  }

  void add(const std::string& sceneName, const std::string& c, const StabilityResult& result, ReportHost& host) {
    page += cat("<h2>", html(sceneName), ": ", html(c), "</h2>\n<p>", html(result.description), " Affected pixels: ", result.affected,
                ". Figure: ", html(result.figure),
                ".</p>\n<table><tr><th>method</th><th>figure</th>"
                "<th>threshold</th><th>result</th><th>also measured</th></tr>\n");
    host.out(cat("\n", sceneName, ": ", c, " (", result.figure, ")\n"));
    for (const auto& f : result.figures) {
      ++total;
      failed += !f.pass;
      broken += !f.broken.empty();
      const std::string verdict = !f.broken.empty() ? "BROKEN: " + f.broken : (f.pass ? "pass" : "fail");
      host.out(formatted("  %-26s %9s  <= %9s  %s%s%s\n", f.method.c_str(), fixed(f.value, 4).c_str(), fixed(f.threshold, 4).c_str(),
                         verdict.c_str(), f.detail.empty() ? "" : "  ", f.detail.c_str()));
      csv += cat(sceneName, ",", c, ",", f.method, ",", std::isnan(f.value) ? std::string() : fixed(f.value, 5), ",",
                 std::isnan(f.threshold) ? std::string() : fixed(f.threshold, 5), ",", f.pass ? 1 : 0, ",\"", f.detail, "\",\"", f.broken,
                 "\"\n");
      page += cat("<tr><td>", html(f.method), "</td><td>", fixed(f.value, 4), "</td><td>", fixed(f.threshold, 4), "</td><td class=\"",
                  f.pass ? "pass" : "fail", "\">", html(verdict), "</td><td>", html(f.detail), "</td></tr>\n");
    }
    page += "</table>\n";
  }
};

}  // namespace

int runReport(const ReportRequest& request, ReportHost& host) {
  const std::filesystem::path& out = request.out;
  std::error_code ec;
  std::filesystem::create_directories(out / "charts", ec);
  std::filesystem::create_directories(out / "strips", ec);
  if (ec) return failed(host, cat("error: cannot create ", out.string(), ": ", ec.message(), "\n"));
  References refs(out / "references", request.options.referenceSpp);
  const auto start = Clock::now();
  Player player(request, host, refs, start);
  auto planned = planJobs(request, host);
  if (!planned) return failed(host, cat("error: ", planned.error(), "\n"));
  for (const auto& n : planned->notes) host.err(cat("note: ", n, "\n"));

  auto results = player.playAll(planned.value());
  if (!results) return failed(host, cat("\nerror: ", results.error(), "\n"));
  host.err(cat("references: ", refs.rendered(), " rendered, ", refs.reused(), " reused from ", (out / "references").string(), "\n"));
  if (auto w = writeSummaryCsv(results.value(), out); !w) return failed(host, cat("error: ", w.error(), "\n"));
  auto charts = writePictures(results.value(), request.options.target, out, host);
  if (!charts) return failed(host, cat("error: ", charts.error(), "\n"));

  std::string page = indexHead(request.options, planned.value(), host);
  for (const auto& r : results.value()) page += indexSection(r);
  page += "</body></html>\n";
  if (auto w = writeFileAtomic(out / "index.html", page); !w) return failed(host, cat("error: ", w.error(), "\n"));
  host.out(summaryTable(results.value()));
  host.out(formatted("wrote %s (%d charts, %zu strips) in %.0f s\n", (out / "index.html").string().c_str(), charts.value(), results->size(),
                     secondsSince(start)));
  return 0;
}

int runStabilityReport(const std::vector<std::string>& scenes, const std::vector<std::string>& cases, const StabilityOptions& options,
                       const std::filesystem::path& out, ReportHost& host) {
  std::error_code ec;
  std::filesystem::create_directories(out, ec);
  if (ec) return failed(host, cat("error: cannot create ", out.string(), ": ", ec.message(), "\n"));
  References refs(out / "references", options.referenceSpp);
  const auto start = Clock::now();
  StabilityReport report(options);
  for (const auto& sceneName : scenes) {
    auto loaded = host.loadScene(sceneName);
    if (!loaded) return failed(host, cat("error: ", loaded.error(), "\n"));
    for (const auto& c : cases) {
      const int index = static_cast<int>(&c - cases.data());
      auto result = runStabilityCase(c, loaded->scene, options, refs, [&](const std::string& what) {
        host.progress(what, index, static_cast<int>(cases.size()), secondsSince(start));
      });
      if (!result) report.cannotRun(sceneName, c, result.error(), host);
      else report.add(sceneName, c, result.value(), host);
    }
  }
  report.page += "</body></html>\n";
  if (auto w = writeFileAtomic(out / "stability.csv", report.csv); !w) return failed(host, cat("error: ", w.error(), "\n"));
  if (auto w = writeFileAtomic(out / "stability.html", report.page); !w) return failed(host, cat("error: ", w.error(), "\n"));
  host.out(formatted("\n%d of %d figures pass; %d broke an invariant. Wrote %s in %.0f s\n", report.total - report.failed, report.total,
                     report.broken, (out / "stability.html").string().c_str(), secondsSince(start)));
  return report.broken > 0 ? 1 : 0;
}

}  // namespace retile::eval
