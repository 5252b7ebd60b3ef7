#pragma once
// Reads a Prometheus text exposition (e.g. the server's /metrics) into numbers.
#include <map>
#include <string>

namespace nidevo::client {

// Series as printed, e.g. `nidevo_frames_total{outcome="ok"}` -> 120.
using MetricSamples = std::map<std::string, double>;

// HTTP GET over libcurl. Throws std::runtime_error naming the URL and the failure.
std::string httpGet(const std::string& url, double timeout_s = 5);
MetricSamples parsePrometheusText(const std::string& text);
// Sum over every series of one metric name (all label values).
double sumOf(const MetricSamples& samples, const std::string& name);
// Value of one series, or 0 when absent.
double valueOf(const MetricSamples& samples, const std::string& series);

}  // namespace nidevo::client
