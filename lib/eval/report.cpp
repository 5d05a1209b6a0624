#include "eval/report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>

namespace adit::eval {
namespace {

std::string format(const char* fmt, ...) {
  char buf[512];
  va_list args;
  va_start(args, fmt);
  std::vsnprintf(buf, sizeof buf, fmt, args);
  va_end(args);
  return buf;
}

std::string statsLine(const char* label, const ErrorStats& s, const char* unit) {
  return format("  %-16s n=%-6zu max %.4f  min %.4f  mean %.4f  median %.4f  rmse %.4f  std %.4f %s\n", label,
                s.count, s.max, s.min, s.mean, s.median, s.rmse, s.std, unit);
}

// ---- JSON helpers: tiny, no dependency, deterministic ----
std::string num(double v) { return std::isfinite(v) ? format("%.9g", v) : "null"; }

std::string quoted(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\', out += c;
    else if (c == '\n') out += "\\n";
    else if (static_cast<unsigned char>(c) < 0x20) out += format("\\u%04x", c);
    else out += c;
  }
  return out + "\"";
}

std::string statsJson(const ErrorStats& s) {
  return format("{\"count\": %zu, \"max\": ", s.count) + num(s.max) + ", \"min\": " + num(s.min) +
         ", \"mean\": " + num(s.mean) + ", \"median\": " + num(s.median) + ", \"rmse\": " + num(s.rmse) +
         ", \"std\": " + num(s.std) + "}";
}

std::string alignmentJson(const EvalResult& r) {
  std::string rot = "[";
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) rot += (i || j ? ", " : "") + num(r.alignment.rotation(i, j));
  const Eigen::Vector3d& t = r.alignment.translation;
  return "{\"mode\": " + quoted(toString(r.align)) + ", \"scale\": " + num(r.alignment.scale) +
         ", \"rotation_row_major\": " + rot + "], \"translation\": [" + num(t.x()) + ", " + num(t.y()) + ", " +
         num(t.z()) + "], \"degenerate\": " + (r.alignment.degenerate ? "true" : "false") + "}";
}

std::string driftJson(const KittiDrift& d) {
  std::string out = std::string("{\"available\": ") + (d.available ? "true" : "false") +
                    format(", \"segments\": %zu", d.segments) +
                    ", \"translation_percent\": " + num(d.translation_percent) +
                    ", \"rotation_deg_per_m\": " + num(d.rotation_deg_per_m) + ", \"per_length\": [";
  for (std::size_t i = 0; i < d.per_length.size(); ++i) {
    const DriftLength& l = d.per_length[i];
    out += (i ? ", " : "") + std::string("{\"length_m\": ") + num(l.length_m) + format(", \"segments\": %zu", l.segments) +
           ", \"translation_percent\": " + num(l.translation_percent) +
           ", \"rotation_deg_per_m\": " + num(l.rotation_deg_per_m) + "}";
  }
  return out + "]}";
}

}  // namespace

std::string formatReport(const EvalResult& r) {
  std::string out = "Trajectory evaluation\n";
  out += format("  poses: %zu ground truth, %zu estimate, %zu matched\n", r.gt_poses, r.est_poses, r.matched_poses);
  if (!r.valid) return out + "  not evaluated: " + r.message + "\n";
  if (!r.message.empty()) out += "  warning: " + r.message + "\n";
  out += format("  duration %.3f s, distance travelled %.3f m (ground truth), %.3f m (estimate)\n", r.duration_s,
                r.gt_distance_m, r.est_distance_m);
  out += "  alignment: " + toString(r.align);
  if (r.align == AlignMode::kSim3) out += format(" (scale %.6f)", r.alignment.scale);
  out += "\n\nAPE (translation, m)\n" + statsLine("all poses", r.ape_m, "m");
  out += "\nRPE (consecutive pairs by path length, as evo_rpe --delta_unit m)\n";
  for (const RpeResult& e : r.rpe) {
    const std::string label = format("%g m", e.delta_m);
    if (e.translation_m.count == 0) {
      out += format("  %-16s no pairs: estimate path shorter than 2 x %g m\n", label.c_str(), e.delta_m);
      continue;
    }
    out += statsLine((label + " trans").c_str(), e.translation_m, "m");
    out += statsLine((label + " rot").c_str(), e.rotation_deg, "deg");
  }
  out += "\nKITTI drift (segments 100..800 m)\n";
  if (!r.drift.available) {
    out += format("  not available: path %.1f m is shorter than the shortest segment\n", r.gt_distance_m);
  } else {
    out += format("  translation %.4f %%   rotation %.6f deg/m   (%zu segments)\n", r.drift.translation_percent,
                  r.drift.rotation_deg_per_m, r.drift.segments);
    for (const DriftLength& l : r.drift.per_length)
      out += format("    %5.0f m: %.4f %%  %.6f deg/m  (%zu)\n", l.length_m, l.translation_percent,
                    l.rotation_deg_per_m, l.segments);
  }
  out += format("\nEnd-point error: %.4f m (%.4f %% of %.3f m travelled)\n", r.end_point.error_m,
                r.end_point.percent_of_distance, r.gt_distance_m);
  return out;
}

std::string toJson(const EvalResult& r) {
  std::string out = std::string("{\n  \"valid\": ") + (r.valid ? "true" : "false") + ",\n";
  out += "  \"message\": " + quoted(r.message) + ",\n";
  out += format("  \"poses\": {\"ground_truth\": %zu, \"estimate\": %zu, \"matched\": %zu, \"non_finite_dropped\": %zu},\n",
                r.gt_poses, r.est_poses, r.matched_poses, r.non_finite_dropped);
  out += "  \"alignment\": " + alignmentJson(r) + ",\n";
  out += "  \"ape_translation_m\": " + statsJson(r.ape_m) + ",\n";
  out += "  \"rpe\": [";
  for (std::size_t i = 0; i < r.rpe.size(); ++i)
    out += std::string(i ? ",\n" : "\n") + "    {\"delta_m\": " + num(r.rpe[i].delta_m) +
           ", \"translation_m\": " + statsJson(r.rpe[i].translation_m) +
           ", \"rotation_deg\": " + statsJson(r.rpe[i].rotation_deg) + "}";
  out += r.rpe.empty() ? "],\n" : "\n  ],\n";
  out += "  \"kitti_drift\": " + driftJson(r.drift) + ",\n";
  out += "  \"end_point\": {\"error_m\": " + num(r.end_point.error_m) +
         ", \"percent_of_distance\": " + num(r.end_point.percent_of_distance) + "},\n";
  out += "  \"distance_m\": {\"ground_truth\": " + num(r.gt_distance_m) + ", \"estimate\": " + num(r.est_distance_m) +
         "},\n";
  out += "  \"duration_s\": " + num(r.duration_s) + "\n}\n";
  return out;
}

std::string formatApeTable(const std::vector<ApeTableRow>& rows, const std::string& title) {
  const bool with_ms = std::any_of(rows.begin(), rows.end(), [](const ApeTableRow& r) { return r.ms_per_sweep.has_value(); });
  std::size_t width = 7;  // "variant"
  for (const ApeTableRow& r : rows) width = std::max(width, r.variant.size());
  const int w = static_cast<int>(width);
  std::string out = title.empty() ? "" : title + "\n";
  std::string header = format("%-*s | %8s | %8s | %8s | %8s | %8s", w, "variant", "max", "min", "mean", "rmse", "std");
  if (with_ms) header += format(" | %11s", "ms/sweep");
  out += header + "\n" + std::string(header.size(), '-') + "\n";
  for (const ApeTableRow& r : rows) {
    const ErrorStats& s = r.ape_m;
    out += format("%-*s | %8.3f | %8.3f | %8.3f | %8.3f | %8.3f", w, r.variant.c_str(), s.max, s.min, s.mean, s.rmse, s.std);
    if (with_ms) out += r.ms_per_sweep ? format(" | %11.2f", *r.ms_per_sweep) : format(" | %11s", "-");
    out += "\n";
  }
  out += "(APE translation after alignment, metres)\n";
  return out;
}

}  // namespace adit::eval
