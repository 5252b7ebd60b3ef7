#include "metrics_scrape.hpp"

#include <curl/curl.h>

#include <cstdlib>
#include <mutex>
#include <sstream>
#include <stdexcept>

namespace nidevo::client {

namespace {

size_t append(char* data, size_t size, size_t count, void* out) {
  static_cast<std::string*>(out)->append(data, size * count);
  return size * count;
}

}  // namespace

std::string httpGet(const std::string& url, double timeout_s) {
  static std::once_flag init;
  std::call_once(init, [] { curl_global_init(CURL_GLOBAL_DEFAULT); });
  CURL* curl = curl_easy_init();
  if (!curl) throw std::runtime_error("libcurl: cannot create a handle");
  std::string body;
  curl_easy_setopt(curl, CURLOPT_URL, url.c_str());
  curl_easy_setopt(curl, CURLOPT_WRITEFUNCTION, append);
  curl_easy_setopt(curl, CURLOPT_WRITEDATA, &body);
  curl_easy_setopt(curl, CURLOPT_TIMEOUT_MS, long(timeout_s * 1000));
  curl_easy_setopt(curl, CURLOPT_NOSIGNAL, 1L);
  const CURLcode rc = curl_easy_perform(curl);
  long http_code = 0;
  curl_easy_getinfo(curl, CURLINFO_RESPONSE_CODE, &http_code);
  curl_easy_cleanup(curl);
  if (rc != CURLE_OK) throw std::runtime_error("GET " + url + ": " + curl_easy_strerror(rc));
  if (http_code != 200)
    throw std::runtime_error("GET " + url + ": HTTP " + std::to_string(http_code));
  return body;
}

MetricSamples parsePrometheusText(const std::string& text) {
  MetricSamples samples;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    // The value follows the last space outside the label braces.
    const size_t close = line.rfind('}');
    const size_t space = line.find(' ', close == std::string::npos ? 0 : close);
    if (space == std::string::npos) continue;
    const std::string series = line.substr(0, space);
    const char* value = line.c_str() + space + 1;
    char* end = nullptr;
    const double v = std::strtod(value, &end);
    if (end == value) continue;
    samples[series] = v;
  }
  return samples;
}

double sumOf(const MetricSamples& samples, const std::string& name) {
  double sum = 0;
  for (auto it = samples.lower_bound(name); it != samples.end(); ++it) {
    const std::string& s = it->first;
    if (s.compare(0, name.size(), name) != 0) break;
    if (s.size() == name.size() || s[name.size()] == '{') sum += it->second;
  }
  return sum;
}

double valueOf(const MetricSamples& samples, const std::string& series) {
  auto it = samples.find(series);
  return it == samples.end() ? 0 : it->second;
}

}  // namespace nidevo::client
