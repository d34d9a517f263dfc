#include "bench_report.h"

#include <filesystem>
#include <fstream>
#include <sstream>

#include "bench_tables.h"
#include "dynorb/core/error.h"
#include "dynorb/io/atomic_file.h"
#include "dynorb/eval/text_format.h"

namespace dynorb {
namespace {

namespace fs = std::filesystem;


std::string EscapeMarkdownCell(const std::string& text) {
  std::string out;
  for (char c : text) out += c == '|' ? std::string("\\|") : std::string(1, c);
  return out;
}

std::string Markdown(const BenchReportContent& r) {
  std::ostringstream md;
  md << "# " << r.title << "\n\n";
  for (const std::string& line : r.summary) md << "- " << line << "\n";
  for (const BenchTable& t : r.tables) {
    md << "\n## " << t.title << "\n\n";
    if (!t.note.empty()) md << t.note << "\n\n";
    md << "|";
    for (const std::string& h : t.header) md << " " << EscapeMarkdownCell(h) << " |";
    md << "\n|";
    for (size_t i = 0; i < t.header.size(); ++i) md << (i == 0 ? "---|" : "---:|");
    md << "\n";
    for (const auto& row : t.rows) {
      md << "|";
      for (const std::string& cell : row) md << " " << EscapeMarkdownCell(cell) << " |";
      md << "\n";
    }
  }
  if (!r.figures.empty()) {
    md << "\n## Figures\n\n";
    for (const BenchFigure& f : r.figures)
      md << "![" << f.caption << "](" << f.path << ")\n\n*" << f.caption << "*\n\n";
  }
  return md.str();
}

constexpr const char* kStyle = R"(
body { font-family: sans-serif; margin: 2em; color: #222; max-width: 1600px; }
h1 { font-size: 1.6em; } h2 { font-size: 1.2em; margin-top: 1.6em; }
table { border-collapse: collapse; margin: 0.5em 0; font-size: 0.9em; }
th, td { border: 1px solid #bbb; padding: 0.25em 0.6em; white-space: nowrap; }
th { background: #eef; } td { text-align: right; font-variant-numeric: tabular-nums; }
td:first-child, th:first-child { text-align: left; }
p.note { color: #555; font-size: 0.9em; max-width: 70em; }
figure { margin: 1em 0; } figure img { max-width: 100%; border: 1px solid #ccc; }
figcaption { color: #555; font-size: 0.9em; }
)";

std::string Html(const BenchReportContent& r) {
  std::ostringstream html;
  html << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>"
       << EscapeXml(r.title) << "</title>\n<style>" << kStyle << "</style>\n</head>\n<body>\n<h1>"
       << EscapeXml(r.title) << "</h1>\n<ul>\n";
  for (const std::string& line : r.summary) html << "<li>" << EscapeXml(line) << "</li>\n";
  html << "</ul>\n";
  for (const BenchTable& t : r.tables) {
    html << "<h2 id=\"" << EscapeXml(t.id) << "\">" << EscapeXml(t.title) << "</h2>\n";
    if (!t.note.empty()) html << "<p class=\"note\">" << EscapeXml(t.note) << "</p>\n";
    html << "<table class=\"bench\" id=\"table-" << EscapeXml(t.id) << "\">\n<thead><tr>";
    for (const std::string& h : t.header) html << "<th>" << EscapeXml(h) << "</th>";
    html << "</tr></thead>\n<tbody>\n";
    for (const auto& row : t.rows) {
      html << "<tr>";
      for (const std::string& cell : row) html << "<td>" << EscapeXml(cell) << "</td>";
      html << "</tr>\n";
    }
    html << "</tbody>\n</table>\n";
  }
  if (!r.figures.empty()) {
    html << "<h2 id=\"figures\">Figures</h2>\n";
    for (const BenchFigure& f : r.figures) {
      html << "<figure><img src=\"" << EscapeXml(f.path) << "\" alt=\"" << EscapeXml(f.caption)
           << "\" loading=\"eager\"><figcaption>" << EscapeXml(f.caption)
           << "</figcaption></figure>\n";
    }
  }
  // Marks the page once every figure has loaded (data-images="loaded/total", broken ones listed):
  // used by the headless-browser test, and shows the reader which plots are missing.
  html << "<p id=\"image-status\" class=\"note\"></p>\n<script>\nwindow.addEventListener('load', "
          "() => {\n"
          "  const imgs = [...document.images];\n"
          "  const bad = imgs.filter(i => !i.complete || i.naturalWidth === 0).map(i => "
          "i.getAttribute('src'));\n"
          "  document.body.dataset.images = (imgs.length - bad.length) + '/' + imgs.length;\n"
          "  document.getElementById('image-status').textContent = bad.length ? 'missing figures: "
          "' + bad.join(', ')\n"
          "      : imgs.length + ' figures loaded';\n});\n</script>\n";
  html << "</body>\n</html>\n";
  return html.str();
}

}  // namespace

nlohmann::json ReadBenchJson(const std::string& path) {
  std::ifstream in(path);
  if (!fs::is_regular_file(path) || !in) throw InputError("file not found: " + path);
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path + ": not valid JSON: " + e.what());
  }
}

void WriteBenchReport(const nlohmann::json& results, const nlohmann::json& published,
                      const std::string& out_dir) {
  const BenchReportContent content = BuildBenchReport(results, published, out_dir);
  WriteFileAtomically((fs::path(out_dir) / "report.md").string(), Markdown(content));
  WriteFileAtomically((fs::path(out_dir) / "report.html").string(), Html(content));
}

}  // namespace dynorb
