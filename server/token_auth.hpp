#pragma once
// Bearer-token authentication: "authorization: Bearer <token>" metadata checked against the
// tokens of a file (one per line, '#' comments). Only SHA-256 digests of the tokens are kept, and
// a presented token is compared with every digest in constant time. reload() swaps in a new set
// atomically, so a SIGHUP changes the tokens without touching open sessions.
#include <grpcpp/grpcpp.h>

#include <array>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace nidevo::server {

class TokenAuthenticator {
 public:
  enum class Result { kOk, kMissing, kWrong };
  using Digest = std::array<unsigned char, 32>;

  // Off: every call passes.
  TokenAuthenticator() = default;
  // Loads `path`; throws std::runtime_error naming the file when it cannot be read or holds no
  // token.
  explicit TokenAuthenticator(std::string path);

  bool enabled() const { return !path_.empty(); }
  // Re-reads the file. Empty on success; else why, and the old tokens stay.
  std::string reload();
  size_t size() const;
  Result check(const grpc::CallbackServerContext& context) const;
  // For tests and the fuzz-free parts: the check on one header value.
  Result checkHeader(const std::string* authorization) const;

  static Digest digest(const std::string& token);
  // The file's tokens; throws std::runtime_error naming the file and what is wrong.
  static std::vector<Digest> readTokenFile(const std::string& path);

 private:
  std::string path_;
  mutable std::mutex mutex_;
  std::shared_ptr<const std::vector<Digest>> digests_;
};

// The status an unauthenticated call gets; never echoes the token.
grpc::Status unauthenticatedStatus(TokenAuthenticator::Result result);

}  // namespace nidevo::server
