#include "odometry_client.hpp"

#include <chrono>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "absl/status/status.h"
#include "grpc/health/v1/health.grpc.pb.h"

namespace nidevo::client {

namespace {

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::chrono::system_clock::time_point after(double seconds) {
  return std::chrono::system_clock::now() + std::chrono::microseconds(int64_t(seconds * 1e6));
}

}  // namespace

std::string readBearerToken(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("--token_file: cannot read " + path);
  for (std::string line; std::getline(in, line);) {
    line = line.substr(0, line.find('#'));
    const auto begin = line.find_first_not_of(" \t\r");
    if (begin == std::string::npos) continue;
    return line.substr(begin, line.find_last_not_of(" \t\r") - begin + 1);
  }
  throw std::runtime_error("--token_file: " + path + " holds no token");
}

std::string statusCodeName(grpc::StatusCode code) {
  // gRPC's codes are Abseil's, value for value.
  return absl::StatusCodeToString(static_cast<absl::StatusCode>(code));
}

Eigen::Isometry3d toIsometry(const v1::Pose& pose) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Quaterniond(pose.qw(), pose.qx(), pose.qy(), pose.qz()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(pose.tx(), pose.ty(), pose.tz());
  return T;
}

void toProto(const Eigen::Isometry3d& T, v1::Pose* pose) {
  const Eigen::Quaterniond q(T.rotation());
  pose->set_tx(T.translation().x());
  pose->set_ty(T.translation().y());
  pose->set_tz(T.translation().z());
  pose->set_qw(q.w());
  pose->set_qx(q.x());
  pose->set_qy(q.y());
  pose->set_qz(q.z());
}

Client::Client(const ChannelOptions& options) : options_(options) {
  grpc::ChannelArguments args;
  args.SetInt(GRPC_ARG_KEEPALIVE_TIME_MS, int(options.keepalive_time_s * 1000));
  args.SetInt(GRPC_ARG_KEEPALIVE_TIMEOUT_MS, int(options.keepalive_timeout_s * 1000));
  args.SetMaxReceiveMessageSize(-1);
  args.SetMaxSendMessageSize(-1);  // the server enforces its own limit and says so
  // gRPC's default first reconnect waits 1 s, growing to 120 s: too slow for a pose stream
  // whose server restarts in a second.
  args.SetInt(GRPC_ARG_INITIAL_RECONNECT_BACKOFF_MS, 200);
  args.SetInt(GRPC_ARG_MIN_RECONNECT_BACKOFF_MS, 200);
  args.SetInt(GRPC_ARG_MAX_RECONNECT_BACKOFF_MS, 2000);
  if (options.http2_stream_window_bytes > 0)
    args.SetInt(GRPC_ARG_HTTP2_STREAM_LOOKAHEAD_BYTES, options.http2_stream_window_bytes);
  if (options.http2_max_frame_bytes > 0)
    args.SetInt(GRPC_ARG_HTTP2_MAX_FRAME_SIZE, options.http2_max_frame_bytes);
  if (!options.load_balancing.empty()) args.SetLoadBalancingPolicyName(options.load_balancing);
  std::shared_ptr<grpc::ChannelCredentials> creds;
  if (options.tls) {
    grpc::SslCredentialsOptions ssl;
    if (!options.ca_file.empty()) ssl.pem_root_certs = readFile(options.ca_file);
    if (options.cert_file.empty() != options.key_file.empty())
      throw std::invalid_argument("--tls_cert_file and --tls_key_file go together");
    if (!options.cert_file.empty()) {
      ssl.pem_cert_chain = readFile(options.cert_file);
      ssl.pem_private_key = readFile(options.key_file);
    }
    creds = grpc::SslCredentials(ssl);
  } else {
    creds = grpc::InsecureChannelCredentials();
  }
  channel_ = grpc::CreateCustomChannel(options.target, creds, args);
  stub_ = v1::OdometryService::NewStub(channel_);
}

void Client::prepare(grpc::ClientContext* context) const {
  context->set_deadline(after(options_.connect_timeout_s));
  addToken(context);
}

void Client::addToken(grpc::ClientContext* context) const {
  if (!options_.bearer_token.empty())
    context->AddMetadata("authorization", "Bearer " + options_.bearer_token);
}

grpc::Status Client::serverInfo(v1::ServerInfo* info) {
  grpc::ClientContext context;
  prepare(&context);
  return stub_->GetServerInfo(&context, v1::GetServerInfoRequest(), info);
}

grpc::Status Client::health(const std::string& service, bool* serving) {
  auto stub = grpc::health::v1::Health::NewStub(channel_);
  grpc::ClientContext context;
  prepare(&context);
  grpc::health::v1::HealthCheckRequest request;
  request.set_service(service);
  grpc::health::v1::HealthCheckResponse response;
  grpc::Status status = stub->Check(&context, request, &response);
  *serving = status.ok() && response.status() == grpc::health::v1::HealthCheckResponse::SERVING;
  return status;
}

std::unique_ptr<Session> Client::open(const SessionOptions& options, ResponseCallback callback) {
  if (!channel_->WaitForConnected(after(options_.connect_timeout_s)))
    throw std::runtime_error("cannot connect to " + options_.target + " within " +
                             std::to_string(options_.connect_timeout_s) + " s");
  std::unique_ptr<Session> session(new Session());
  if (options.deadline_s > 0) session->context_.set_deadline(after(options.deadline_s));
  addToken(&session->context_);
  session->stream_ = stub_->Track(&session->context_);
  auto* config = session->request_.mutable_config();
  auto* camera = config->mutable_camera();
  camera->set_fx(options.camera.fx);
  camera->set_fy(options.camera.fy);
  camera->set_cx(options.camera.cx);
  camera->set_cy(options.camera.cy);
  camera->set_width(uint32_t(options.camera.width));
  camera->set_height(uint32_t(options.camera.height));
  if (!options.camera.distortion.none()) {
    const nidevo::Distortion& d = options.camera.distortion;
    auto* lens = camera->mutable_distortion();
    lens->set_k1(d.k1);
    lens->set_k2(d.k2);
    lens->set_p1(d.p1);
    lens->set_p2(d.p2);
    lens->set_k3(d.k3);
  }
  config->set_color_encoding(options.color_encoding);
  config->set_depth_encoding(options.depth_encoding);
  config->set_depth_scale(options.camera.depth_scale);
  config->set_overload_policy(options.overload_policy);
  config->set_queue_capacity(options.queue_capacity);
  config->set_client_name(options.client_name);
  if (options.initial_pose) toProto(*options.initial_pose, config->mutable_initial_pose());
  session->stream_->Write(session->request_);  // a failure shows in finish()
  if (callback) {
    Session* s = session.get();
    session->reader_ = std::thread([s, callback] {
      v1::TrackResponse response;
      while (s->stream_->Read(&response)) callback(response);
    });
  }
  return session;
}

bool Session::send(const v1::Frame& frame) {
  if (writes_done_) return false;
  *request_.mutable_frame() = frame;
  return stream_->Write(request_);
}

bool Session::send(v1::Frame* frame) {
  if (writes_done_) return false;
  request_.mutable_frame()->Swap(frame);
  return stream_->Write(request_);
}

bool Session::receive(v1::TrackResponse* response) { return stream_->Read(response); }

grpc::Status Session::finish() {
  if (finished_) return status_;
  if (!writes_done_) {
    writes_done_ = true;
    stream_->WritesDone();
  }
  if (reader_.joinable()) {
    reader_.join();
  } else {
    v1::TrackResponse ignored;  // answers the caller did not read
    while (stream_->Read(&ignored)) {
    }
  }
  status_ = stream_->Finish();
  finished_ = true;
  return status_;
}

void Session::cancel() {
  context_.TryCancel();
  finish();
}

Session::~Session() {
  if (!finished_) cancel();
}

}  // namespace nidevo::client
