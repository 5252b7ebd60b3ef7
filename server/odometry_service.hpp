#pragma once
// The nidevo.v1.OdometryService: admits streams up to the session limit, keeps the set of open
// sessions for the idle reaper, and answers GetServerInfo.
#include <condition_variable>
#include <mutex>
#include <set>
#include <thread>

#include "nidevo/v1/odometry.grpc.pb.h"
#include "server_config.hpp"
#include "server_metrics.hpp"
#include "session.hpp"
#include "token_auth.hpp"
#include "worker_pool.hpp"

namespace nidevo::server {

class OdometryService final : public v1::OdometryService::CallbackService {
 public:
  // `auth` (may be off) checks every call of this service; health is a separate service.
  OdometryService(const ServerConfig& config, WorkerPool& pool, ServerMetrics& metrics,
                  const TokenAuthenticator& auth);
  ~OdometryService() override;  // stops the reaper (idle sessions, memory when none is open)

  grpc::ServerBidiReactor<v1::TrackRequest, v1::TrackResponse>* Track(
      grpc::CallbackServerContext* context) override;
  grpc::ServerUnaryReactor* GetServerInfo(grpc::CallbackServerContext* context,
                                          const v1::GetServerInfoRequest* request,
                                          v1::ServerInfo* info) override;

  int activeSessions();
  // New streams fail with UNAVAILABLE from now on; open ones go on.
  void beginDrain();

 private:
  // Ends sessions past the idle timeout and, once no session is open, gives freed memory back.
  void reapIdleSessions();
  void sessionDone(Session* session);
  // OK, or the UNAUTHENTICATED status (counted) when the call's token does not pass.
  grpc::Status authenticate(const grpc::CallbackServerContext& context);

  const ServerConfig& config_;
  WorkerPool& pool_;
  ServerMetrics& metrics_;
  const TokenAuthenticator& auth_;
  std::mutex mutex_;
  std::condition_variable stop_cv_;
  bool stopping_ = false;
  bool draining_ = false;
  // A session ended since memory was last given back (see releaseFreedMemory).
  bool ended_since_release_ = false;
  std::set<Session*> sessions_;
  std::thread reaper_;
};

}  // namespace nidevo::server
