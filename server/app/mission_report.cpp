#include "app/mission_report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "scanplan/geometry/pose.hpp"

namespace scanplan::server {
namespace {

using nlohmann::json;

std::string escaped(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string base64(const std::vector<std::uint8_t>& bytes) {
  static constexpr char kDigits[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const std::uint32_t n =
        (static_cast<std::uint32_t>(bytes[i]) << 16) |
        (i + 1 < bytes.size() ? static_cast<std::uint32_t>(bytes[i + 1]) << 8 : 0) |
        (i + 2 < bytes.size() ? bytes[i + 2] : 0u);
    out += kDigits[(n >> 18) & 63];
    out += kDigits[(n >> 12) & 63];
    out += i + 1 < bytes.size() ? kDigits[(n >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? kDigits[n & 63] : '=';
  }
  return out;
}

std::string num(double v, int decimals = 1) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

std::string metres2(double v) {
  return num(v, 0) + " m²";
}

double coverage_pct(const MapAreas& a) {
  const double total = a.completed_m2 + a.low_resolution_m2 + a.unscanned_m2;
  return total > 0 ? 100 * a.completed_m2 / total : 0;
}

const char* kind_colour(const std::string& kind) {
  if (kind == "victim") return "#d62728";
  if (kind == "hazard") return "#ff7f0e";
  if (kind == "blocked") return "#7f3fbf";
  return "#1f77b4";
}

// The top view with the marks numbered as in the table below it, north up, with a scale bar.
std::string map_section(const ReportInput& in) {
  std::string h = "<h2>Top view</h2>";
  if (!in.regions.png) return h + "<p>No scan is in the map yet.</p>";
  const LayerGeometry& g = in.regions.geometry;
  h += "<figure class=\"map\"><div class=\"map-wrap\"><img alt=\"top view of the map\" "
       "src=\"data:image/png;base64," +
       base64(*in.regions.png) + "\">";
  const double w = g.max_x - g.min_x, hgt = g.max_y - g.min_y;
  for (std::size_t i = 0; i < in.annotations.size(); ++i) {
    const Annotation& a = in.annotations[i];
    if (!(w > 0 && hgt > 0) || a.x < g.min_x || a.x > g.max_x || a.y < g.min_y || a.y > g.max_y) {
      continue;
    }
    h += "<span class=\"mark\" style=\"left:" + num(100 * (a.x - g.min_x) / w, 2) +
         "%;top:" + num(100 * (g.max_y - a.y) / hgt, 2) + "%;background:" + kind_colour(a.kind) +
         "\" title=\"" + escaped(a.kind) + "\">" + std::to_string(i + 1) + "</span>";
  }
  // A bar of a round length near a fifth of the width.
  double bar_m = 1;
  for (const double step : {1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0, 200.0, 500.0}) {
    if (step <= w / 5) bar_m = step;
  }
  h += "</div><figcaption><span class=\"scale\" style=\"width:" +
       num(100 * bar_m / std::max(w, 1e-9), 2) + "%\"></span> " + num(bar_m, 0) +
       " m · north up · x " + num(g.min_x) + "…" + num(g.max_x) + " m, y " + num(g.min_y) + "…" +
       num(g.max_y) +
       " m (map frame) · flesh: scan-completed, yellow: low resolution (movable), blue: low "
       "resolution (not movable), dark: unscanned</figcaption></figure>";
  return h;
}

std::string marks_section(const ReportInput& in) {
  std::string h = "<h2>Marks (" + std::to_string(in.annotations.size()) + ")</h2>";
  if (in.annotations.empty()) return h + "<p>No victim, hazard, blockage or note was marked.</p>";
  h += "<table><tr><th>#</th><th>kind</th><th>x, y, z (m)</th><th>text</th><th>by</th><th>when "
       "(UTC)</th></tr>";
  for (std::size_t i = 0; i < in.annotations.size(); ++i) {
    const Annotation& a = in.annotations[i];
    h += "<tr><td>" + std::to_string(i + 1) + "</td><td class=\"kind-" + escaped(a.kind) + "\">" +
         escaped(a.kind) + "</td><td>" + num(a.x, 2) + ", " + num(a.y, 2) + ", " + num(a.z, 2) +
         "</td><td>" + escaped(a.text) + "</td><td>" + escaped(a.author) + "</td><td>" +
         escaped(a.created_at) + "</td></tr>";
  }
  return h + "</table>";
}

std::string scans_section(const ReportInput& in) {
  std::string h = "<h2>Scans (" + std::to_string(in.scans.size()) + ")</h2>";
  if (in.scans.empty()) return h + "<p>No scan yet.</p>";
  h += "<table><tr><th>scan</th><th>robot</th><th>received (UTC)</th><th>placed x, y, z (m), "
       "heading (°)</th><th>points</th><th>match</th></tr>";
  for (const StoredScan& s : in.scans) {
    std::string match = "the reference (first scan)";
    if (s.match) {
      match = s.match->applied ? "applied (" + escaped(s.match->method) + ", " +
                                     num(100 * s.match->inlier_ratio, 0) + " % on the map)"
                               : "not applied: " + escaped(s.match->reason);
    }
    if (const auto w = in.waiting.find(s.id); w != in.waiting.end()) {
      match += "; waiting outside the map: " + escaped(w->second);
    }
    if (s.excluded) match += "; taken out of the map: " + escaped(s.excluded->reason);
    const Pose& p = s.placed;
    h += "<tr><td>" + std::to_string(s.id) + "</td><td>" + escaped(s.robot) + "</td><td>" +
         escaped(s.received_at) + "</td><td>" + num(p.x, 2) + ", " + num(p.y, 2) + ", " +
         num(p.z, 2) + ", " + num(rad2deg(p.yaw), 1) + "</td><td>" + std::to_string(s.points) +
         "</td><td>" + match + "</td></tr>";
  }
  return h + "</table>";
}

// A bar per scan: the completed and low-resolution shares of the target region after it.
std::string coverage_section(const ReportInput& in) {
  std::string h = "<h2>Coverage</h2><p>Now: " + num(coverage_pct(in.areas), 1) +
                  " % of the target region scan-completed (" + metres2(in.areas.completed_m2) +
                  " completed, " + metres2(in.areas.low_resolution_m2) + " low resolution, " +
                  metres2(in.areas.unscanned_m2) + " unscanned).</p>";
  if (in.areas_after.empty()) return h;
  const double bar = 24, gap = 6, height = 120;
  const double width = static_cast<double>(in.areas_after.size()) * (bar + gap) + 40;
  h += "<svg class=\"chart\" viewBox=\"0 0 " + num(width, 0) + " " + num(height + 30, 0) +
       "\" width=\"" + num(width, 0) + "\" height=\"" + num(height + 30, 0) +
       "\" role=\"img\" aria-label=\"coverage after each scan\">";
  h += "<text x=\"0\" y=\"10\" class=\"axis\">100 %</text><text x=\"0\" y=\"" + num(height, 0) +
       "\" class=\"axis\">0 %</text>";
  double x = 36;
  for (const auto& [id, a] : in.areas_after) {
    const double total = a.completed_m2 + a.low_resolution_m2 + a.unscanned_m2;
    const double c = total > 0 ? height * a.completed_m2 / total : 0;
    const double m = total > 0 ? height * a.low_resolution_m2 / total : 0;
    h += "<rect x=\"" + num(x, 1) + "\" y=\"" + num(height - c, 1) + "\" width=\"" + num(bar, 0) +
         "\" height=\"" + num(c, 1) + "\" fill=\"#f4c7a1\"><title>scan " + std::to_string(id) +
         ": " + num(coverage_pct(a), 1) + " % completed</title></rect>";
    h += "<rect x=\"" + num(x, 1) + "\" y=\"" + num(height - c - m, 1) + "\" width=\"" +
         num(bar, 0) + "\" height=\"" + num(m, 1) + "\" fill=\"#e8c53a\"></rect>";
    h += "<text x=\"" + num(x + bar / 2, 1) + "\" y=\"" + num(height + 14, 0) +
         "\" class=\"axis\" text-anchor=\"middle\">" + std::to_string(id) + "</text>";
    x += bar + gap;
  }
  return h +
         "</svg><p class=\"muted\">Bars: scan-completed (flesh) and low resolution (yellow) "
         "after each scan, as a share of the target region; below, the scan.</p>";
}

// A decision in a line: what, and the details a reader needs (who, which robot and point, why).
std::string decision_text(const SessionEvent& e) {
  const json d = json::parse(e.json, nullptr, false);
  std::string text = e.kind;
  if (!d.is_object()) return text;
  const auto field = [&](const char* key, const char* label) {
    if (!d.contains(key) || d[key].is_null()) return;
    const json& v = d[key];
    std::string value = v.is_string()   ? v.get<std::string>()
                        : v.is_number() ? num(v.get<double>(), v.is_number_integer() ? 0 : 1)
                                        : v.dump();
    if (!value.empty()) text += std::string(" · ") + label + value;
  };
  field("robot", "");
  field("candidate", "candidate ");
  field("scan", "scan ");
  if (d.contains("x") && d.contains("y") && d["x"].is_number() && d["y"].is_number()) {
    text += " · at (" + num(d["x"].get<double>()) + ", " + num(d["y"].get<double>()) + ")";
  }
  field("by", "by ");
  field("reason", "");
  field("message", "");
  return escaped(text);
}

std::string decisions_section(const ReportInput& in) {
  std::string h = "<h2>Decisions (" + std::to_string(in.decisions.size()) + ")</h2>";
  if (in.decisions.empty()) return h + "<p>No decision was recorded.</p>";
  h += "<table><tr><th>when (UTC)</th><th>what</th></tr>";
  for (const SessionEvent& e : in.decisions) {
    h += "<tr><td>" + escaped(e.at) + "</td><td>" + decision_text(e) + "</td></tr>";
  }
  return h + "</table>";
}

constexpr const char* kStyle =
    "body{font:14px/1.4 system-ui,sans-serif;margin:24px;color:#111}"
    "h1{font-size:22px;margin:0 0 4px}h2{font-size:17px;margin:22px 0 6px;border-bottom:1px solid "
    "#bbb}table{border-collapse:collapse;width:100%}th,td{border:1px solid #ccc;padding:3px "
    "6px;text-align:left;vertical-align:top}th{background:#eee}.muted{color:#555}"
    ".map-wrap{position:relative;display:inline-block;max-width:100%}.map-wrap "
    "img{display:block;max-width:100%;image-rendering:pixelated}.mark{position:absolute;"
    "transform:translate(-50%,-50%);color:#fff;border-radius:50%;min-width:18px;height:18px;"
    "font-size:11px;text-align:center;line-height:18px;border:1px solid #000}"
    ".scale{display:inline-block;height:6px;border:1px solid #000;border-top:0;vertical-align:"
    "middle}.kind-victim{color:#d62728;font-weight:600}.kind-hazard{color:#c25400}"
    ".axis{font-size:10px;fill:#333}@media print{body{margin:10mm}h2{break-after:avoid}"
    "tr{break-inside:avoid}}";

}  // namespace

std::string mission_report_html(const ReportInput& in) {
  std::string area = "the default (a 200 m square around the first scan)";
  if (in.params.target) {
    area = std::to_string(in.params.target->corners().size()) + " corners, " +
           metres2(in.params.target->area_m2());
  }
  std::string h =
      "<!DOCTYPE html><html lang=\"en\"><head><meta charset=\"utf-8\"><title>scanplan mission "
      "report</title><style>" +
      std::string(kStyle) +
      "</style></head><body><h1>scanplan mission report</h1><p class=\"muted\">Session " +
      escaped(in.session_dir) + " · generated " + escaped(in.generated_at) +
      " UTC · coordinates in metres in the map frame (the first scan's: origin at its position, "
      "x along its heading, z up)</p>";
  h += "<p>" + std::to_string(in.scans.size()) + " scans · " + num(coverage_pct(in.areas), 1) +
       " % of the target region scan-completed · target area: " + area + " · " +
       std::to_string(in.params.planner.no_go.size()) + " no-go zones · " +
       std::to_string(in.annotations.size()) + " marks</p>";
  h += map_section(in) + marks_section(in) + scans_section(in) + coverage_section(in) +
       decisions_section(in);
  return h + "</body></html>\n";
}

}  // namespace scanplan::server
