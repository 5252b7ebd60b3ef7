#pragma once
// A small C++ client for nidevo.v1: connect, open a session with a camera and options, send
// frames, receive one answer per frame in order, close. One write in flight (each send blocks
// while HTTP/2 flow control pushes back); every gRPC status is surfaced with its message.
#include <grpcpp/grpcpp.h>

#include <Eigen/Geometry>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <thread>

#include "nidevo/odometry/camera.hpp"
#include "nidevo/v1/odometry.grpc.pb.h"

namespace nidevo::client {

struct ChannelOptions {
  std::string target = "127.0.0.1:50051";  // host:port, or any gRPC target (dns:///svc:50051)
  bool tls = false;
  std::string ca_file;  // PEM roots for TLS; empty: the system's
  // Mutual TLS: this client's PEM certificate chain and private key (both or neither).
  std::string cert_file;
  std::string key_file;
  // Sent as "authorization: Bearer <token>" on every call; empty: none.
  std::string bearer_token;
  // Keepalive matching the server's defaults (it accepts pings every 10 s or slower).
  double keepalive_time_s = 60;
  double keepalive_timeout_s = 20;
  double connect_timeout_s = 5;  // open() and the unary calls wait this long for a connection
  // HTTP/2 flow control of what comes back (0: gRPC's defaults); the server's own settings
  // govern the frames sent.
  int http2_stream_window_bytes = 0;
  int http2_max_frame_bytes = 0;
  std::string load_balancing = "";  // e.g. "round_robin" with a dns:/// target (headless Service)
};

struct SessionOptions {
  Camera camera;
  v1::ColorEncoding color_encoding = v1::COLOR_ENCODING_GRAY8;
  v1::DepthEncoding depth_encoding = v1::DEPTH_ENCODING_UINT16;
  v1::OverloadPolicy overload_policy = v1::OVERLOAD_POLICY_BLOCK;
  uint32_t queue_capacity = 0;  // 0: server default
  std::string client_name;
  double deadline_s = 0;  // whole-stream deadline; 0: none
  // T_world_cam of the first frame (SessionConfig.initial_pose); none: identity.
  std::optional<Eigen::Isometry3d> initial_pose;
};

// Receives every answer, in the order the server sends it, on the session's reader thread.
using ResponseCallback = std::function<void(const v1::TrackResponse&)>;

class Session {
 public:
  ~Session();  // cancels if still open
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;

  // Blocks while flow control pushes back. False when the stream has ended; finish() says why.
  bool send(const v1::Frame& frame);
  // The same without copying the frame's bytes (a raw VGA frame is 0.9 MB): `frame` is swapped
  // into the request, and holds the previous frame's buffers afterwards for reuse.
  bool send(v1::Frame* frame);
  // Blocking receive, only for sessions opened without a callback. False at the end of stream.
  bool receive(v1::TrackResponse* response);
  // Half-closes, waits for the remaining answers (callback sessions) and returns the status.
  grpc::Status finish();
  // Abandons the stream (the server frees the session).
  void cancel();

 private:
  friend class Client;
  Session() = default;

  grpc::ClientContext context_;
  std::unique_ptr<grpc::ClientReaderWriter<v1::TrackRequest, v1::TrackResponse>> stream_;
  v1::TrackRequest request_;
  std::thread reader_;
  bool writes_done_ = false;
  bool finished_ = false;
  grpc::Status status_;
};

class Client {
 public:
  explicit Client(const ChannelOptions& options);

  // Sends the session's config. Throws std::runtime_error if the channel cannot connect.
  std::unique_ptr<Session> open(const SessionOptions& options, ResponseCallback callback = {});
  grpc::Status serverInfo(v1::ServerInfo* info);
  // grpc.health.v1 Check; `serving` is true for SERVING.
  grpc::Status health(const std::string& service, bool* serving);

  const std::shared_ptr<grpc::Channel>& channel() const { return channel_; }

 private:
  // The connect deadline and the bearer token, on a unary call's context.
  void prepare(grpc::ClientContext* context) const;
  // The "authorization: Bearer" metadata when the options hold a token; streams and unary calls.
  void addToken(grpc::ClientContext* context) const;

  ChannelOptions options_;
  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<v1::OdometryService::Stub> stub_;
};

// T_world_cam of an answer.
Eigen::Isometry3d toIsometry(const v1::Pose& pose);
void toProto(const Eigen::Isometry3d& T, v1::Pose* pose);

// The first token of a token file (one per line, '#' comments), as the server reads them.
// Throws std::runtime_error naming the file when it cannot be read or holds no token.
std::string readBearerToken(const std::string& path);

// Human name of a gRPC status code, e.g. "RESOURCE_EXHAUSTED".
std::string statusCodeName(grpc::StatusCode code);

}  // namespace nidevo::client
