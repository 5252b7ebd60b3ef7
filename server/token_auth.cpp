#include "token_auth.hpp"

#include <openssl/crypto.h>
#include <openssl/evp.h>

#include <fstream>
#include <stdexcept>

namespace nidevo::server {

namespace {

constexpr char kBearer[] = "Bearer ";

std::string trim(const std::string& s) {
  const auto begin = s.find_first_not_of(" \t\r");
  if (begin == std::string::npos) return "";
  return s.substr(begin, s.find_last_not_of(" \t\r") - begin + 1);
}

}  // namespace

TokenAuthenticator::TokenAuthenticator(std::string path) : path_(std::move(path)) {
  digests_ = std::make_shared<const std::vector<Digest>>(readTokenFile(path_));
}

TokenAuthenticator::Digest TokenAuthenticator::digest(const std::string& token) {
  Digest d{};
  unsigned int size = 0;
  if (EVP_Digest(token.data(), token.size(), d.data(), &size, EVP_sha256(), nullptr) != 1 ||
      size != d.size())
    throw std::runtime_error("SHA-256 failed");
  return d;
}

std::vector<TokenAuthenticator::Digest> TokenAuthenticator::readTokenFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("--token_file: cannot read " + path);
  std::vector<Digest> digests;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const std::string token = trim(line.substr(0, line.find('#')));
    if (token.empty()) continue;
    if (token.find_first_of(" \t") != std::string::npos)
      throw std::runtime_error("--token_file: " + path + ":" + std::to_string(line_no) +
                               ": a token has no blanks");
    digests.push_back(digest(token));
  }
  if (digests.empty()) throw std::runtime_error("--token_file: " + path + " holds no token");
  return digests;
}

std::string TokenAuthenticator::reload() {
  if (!enabled()) return "";
  try {
    auto fresh = std::make_shared<const std::vector<Digest>>(readTokenFile(path_));
    std::lock_guard<std::mutex> lock(mutex_);
    digests_ = std::move(fresh);
    return "";
  } catch (const std::exception& e) {
    return e.what();
  }
}

size_t TokenAuthenticator::size() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return digests_ ? digests_->size() : 0;
}

TokenAuthenticator::Result TokenAuthenticator::checkHeader(const std::string* authorization) const {
  if (!enabled()) return Result::kOk;
  if (!authorization || authorization->rfind(kBearer, 0) != 0) return Result::kMissing;
  const Digest presented = digest(authorization->substr(sizeof(kBearer) - 1));
  std::shared_ptr<const std::vector<Digest>> digests;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    digests = digests_;
  }
  // Every digest is compared, each in constant time: the time says nothing of which matched.
  bool match = false;
  for (const Digest& d : *digests)
    match |= CRYPTO_memcmp(d.data(), presented.data(), d.size()) == 0;
  return match ? Result::kOk : Result::kWrong;
}

TokenAuthenticator::Result TokenAuthenticator::check(
    const grpc::CallbackServerContext& context) const {
  if (!enabled()) return Result::kOk;
  const auto& metadata = context.client_metadata();
  const auto it = metadata.find("authorization");
  if (it == metadata.end()) return checkHeader(nullptr);
  const std::string value(it->second.data(), it->second.size());
  return checkHeader(&value);
}

grpc::Status unauthenticatedStatus(TokenAuthenticator::Result result) {
  return grpc::Status(grpc::StatusCode::UNAUTHENTICATED,
                      result == TokenAuthenticator::Result::kMissing
                          ? "missing bearer token: send metadata 'authorization: Bearer <token>'"
                          : "bearer token not accepted");
}

}  // namespace nidevo::server
