#include "report.hpp"

#include <algorithm>
#include <cstdarg>
#include <cstdio>
#include <map>
#include <set>

namespace nidevo::bench {

namespace {

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

std::string line(const char* format, ...) __attribute__((format(printf, 1, 2)));
std::string line(const char* format, ...) {
  char buffer[512];
  va_list args;
  va_start(args, format);
  std::vsnprintf(buffer, sizeof(buffer), format, args);
  va_end(args);
  return buffer;
}

std::string jsonString(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

}  // namespace

std::string formatTable(const std::vector<MethodRun>& runs) {
  std::string out =
      line("%-34s %-24s %6s %9s %9s %8s %6s %6s %8s %8s\n", "sequence", "method", "frames", "ATE m",
           "RPE t m", "RPE deg", "fail", "silent", "med ms", "p95 ms");
  for (const auto& r : runs)
    out += line("%-34s %-24s %6zu %9.4f %9.4f %8.3f %6d %6d %8.2f %8.2f\n", r.sequence.c_str(),
                r.method.c_str(), r.frames, r.ate_rmse_m, r.rpe_translation_rmse_m,
                r.rpe_rotation_rmse_deg, r.failures, r.silent_failures, r.median_ms, r.p95_ms);
  return out;
}

std::string formatSummary(const std::vector<MethodRun>& runs) {
  std::map<std::string, std::vector<const MethodRun*>> by_method;
  std::map<std::string, const MethodRun*> best_of_sequence, nidevo_of_sequence;
  for (const auto& r : runs) {
    by_method[r.method].push_back(&r);
    auto& best = best_of_sequence[r.sequence];
    if (!best || r.ate_rmse_m < best->ate_rmse_m) best = &r;
    if (r.method == "nidevo") nidevo_of_sequence[r.sequence] = &r;
  }
  std::string out = line("%-24s %10s %10s %5s %7s %8s %13s\n", "method", "median ATE", "max ATE",
                         "wins", "silent", "med ms", "time/nidevo");
  for (const auto& [method, list] : by_method) {
    std::vector<double> ates, times, ratios;
    int wins = 0, silent = 0;
    for (const MethodRun* r : list) {
      ates.push_back(r->ate_rmse_m);
      times.push_back(r->median_ms);
      wins += best_of_sequence[r->sequence] == r;
      silent += r->silent_failures;
      const auto it = nidevo_of_sequence.find(r->sequence);
      if (it != nidevo_of_sequence.end() && it->second->median_ms > 0)
        ratios.push_back(r->median_ms / it->second->median_ms);
    }
    const std::string ratio = ratios.empty() ? "-" : line("x%.2f", median(ratios));
    out += line("%-24s %10.4f %10.4f %5d %7d %8.2f %13s\n", method.c_str(), median(ates),
                *std::max_element(ates.begin(), ates.end()), wins, silent, median(times),
                ratio.c_str());
  }
  return out;
}

std::string formatCsv(const std::vector<MethodRun>& runs) {
  std::string out =
      "sequence,method,frames,ate_rmse_m,rpe_translation_rmse_m,rpe_rotation_rmse_deg,failures,"
      "silent_failures,median_ms,p95_ms\n";
  for (const auto& r : runs)
    out += line("\"%s\",%s,%zu,%.6f,%.6f,%.4f,%d,%d,%.3f,%.3f\n", r.sequence.c_str(),
                r.method.c_str(), r.frames, r.ate_rmse_m, r.rpe_translation_rmse_m,
                r.rpe_rotation_rmse_deg, r.failures, r.silent_failures, r.median_ms, r.p95_ms);
  return out;
}

std::string formatJson(const std::vector<MethodRun>& runs) {
  std::string out = "[\n";
  for (size_t i = 0; i < runs.size(); ++i) {
    const MethodRun& r = runs[i];
    out += "  {\"sequence\": " + jsonString(r.sequence) + ", \"method\": " + jsonString(r.method) +
           line(
               ", \"frames\": %zu, \"ate_rmse_m\": %.6f, \"rpe_translation_rmse_m\": %.6f, "
               "\"rpe_rotation_rmse_deg\": %.4f, \"failures\": %d, \"silent_failures\": %d, "
               "\"median_ms\": %.3f, \"p95_ms\": %.3f}",
               r.frames, r.ate_rmse_m, r.rpe_translation_rmse_m, r.rpe_rotation_rmse_deg,
               r.failures, r.silent_failures, r.median_ms, r.p95_ms) +
           (i + 1 < runs.size() ? ",\n" : "\n");
  }
  return out + "]\n";
}

}  // namespace nidevo::bench
