#include "odometry_service.hpp"

#include <iostream>

#include "memory_release.hpp"

namespace nidevo::server {

OdometryService::OdometryService(const ServerConfig& config, WorkerPool& pool,
                                 ServerMetrics& metrics, const TokenAuthenticator& auth)
    : config_(config), pool_(pool), metrics_(metrics), auth_(auth) {
  reaper_ = std::thread([this] { reapIdleSessions(); });
}

OdometryService::~OdometryService() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  stop_cv_.notify_all();
  reaper_.join();
}

grpc::Status OdometryService::authenticate(const grpc::CallbackServerContext& context) {
  const TokenAuthenticator::Result result = auth_.check(context);
  if (result == TokenAuthenticator::Result::kOk) return grpc::Status::OK;
  metrics_.unauthenticated(result == TokenAuthenticator::Result::kMissing);
  return unauthenticatedStatus(result);
}

grpc::ServerBidiReactor<v1::TrackRequest, v1::TrackResponse>* OdometryService::Track(
    grpc::CallbackServerContext* context) {
  if (grpc::Status status = authenticate(*context); !status.ok()) {
    metrics_.sessionEnded(status.error_code());
    return new RejectedStream(status);
  }
  std::lock_guard<std::mutex> lock(mutex_);
  if (draining_) {
    metrics_.sessionEnded(grpc::StatusCode::UNAVAILABLE);
    return new RejectedStream(grpc::Status(grpc::StatusCode::UNAVAILABLE,
                                           "server is shutting down; use another replica"));
  }
  if (int(sessions_.size()) >= config_.max_sessions) {
    std::cerr << "nidevo-server: session refused: at the limit of " << config_.max_sessions
              << " sessions\n";
    metrics_.sessionEnded(grpc::StatusCode::RESOURCE_EXHAUSTED);
    return new RejectedStream(
        grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED,
                     "server at its limit of " + std::to_string(config_.max_sessions) +
                         " concurrent sessions; retry later or use another replica"));
  }
  SessionEnvironment env;
  env.config = &config_;
  env.pool = &pool_;
  env.metrics = &metrics_;
  env.on_done = [this](Session* s) { sessionDone(s); };
  auto* session = new Session(context, std::move(env));
  sessions_.insert(session);
  metrics_.activeSessions(+1);
  return session;
}

void OdometryService::sessionDone(Session* session) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (sessions_.erase(session)) metrics_.activeSessions(-1);
  ended_since_release_ = true;
}

void OdometryService::beginDrain() {
  std::lock_guard<std::mutex> lock(mutex_);
  draining_ = true;
}

int OdometryService::activeSessions() {
  std::lock_guard<std::mutex> lock(mutex_);
  return int(sessions_.size());
}

void OdometryService::reapIdleSessions() {
  // A tenth of the timeout (at most 1 s) keeps the overshoot small.
  const auto period =
      std::chrono::duration<double>(std::min(1.0, std::max(0.01, config_.idle_timeout_s / 10)));
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stopping_) {
    stop_cv_.wait_for(lock, period);
    if (stopping_) break;
    const Clock::time_point now = Clock::now();
    for (Session* s : sessions_) s->expireIfIdle(now);
    if (sessions_.empty() && ended_since_release_) {
      ended_since_release_ = false;
      lock.unlock();  // a new session need not wait for the trim
      if (releaseFreedMemory()) metrics_.memoryReleased();
      lock.lock();
    }
  }
}

grpc::ServerUnaryReactor* OdometryService::GetServerInfo(grpc::CallbackServerContext* context,
                                                         const v1::GetServerInfoRequest*,
                                                         v1::ServerInfo* info) {
  auto* reactor = context->DefaultReactor();
  if (grpc::Status status = authenticate(*context); !status.ok()) {
    reactor->Finish(status);
    return reactor;
  }
  info->set_version(NIDEVO_VERSION);
  info->set_api("nidevo.v1");
  info->set_max_sessions(uint32_t(config_.max_sessions));
  info->set_active_sessions(uint32_t(activeSessions()));
  info->set_max_message_bytes(uint64_t(config_.max_message_bytes));
  info->set_default_queue_capacity(uint32_t(config_.default_queue_capacity));
  info->set_max_queue_capacity(uint32_t(config_.max_queue_capacity));
  info->set_idle_timeout_seconds(config_.idle_timeout_s);
  info->set_worker_threads(uint32_t(pool_.size()));
  for (auto e : {v1::COLOR_ENCODING_RGB8, v1::COLOR_ENCODING_BGR8, v1::COLOR_ENCODING_GRAY8,
                 v1::COLOR_ENCODING_JPEG, v1::COLOR_ENCODING_PNG})
    info->add_color_encodings(e);
  for (auto e : {v1::DEPTH_ENCODING_UINT16, v1::DEPTH_ENCODING_FLOAT32, v1::DEPTH_ENCODING_PNG16})
    info->add_depth_encodings(e);
  reactor->Finish(grpc::Status::OK);
  return reactor;
}

}  // namespace nidevo::server
