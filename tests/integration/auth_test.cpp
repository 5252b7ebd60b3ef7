// Bearer tokens and mutual TLS against the real server.
#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <thread>

#include "metrics_scrape.hpp"
#include "server_process.hpp"
#include "service_fixtures.hpp"

namespace nidevo::test {
namespace {

using namespace std::chrono_literals;

client::ChannelOptions optionsFor(const ServerProcess& server, const std::string& token) {
  client::ChannelOptions options;
  options.target = server.target();
  options.connect_timeout_s = 10;
  options.bearer_token = token;
  return options;
}

grpc::Status streamStatus(const ServerProcess& server, const std::string& token) {
  client::Client client(optionsFor(server, token));
  return streamSequence(client, renderOffice(2, 1), client::parseFrameEncoding("raw")).status;
}

void writeTokens(const std::string& path, const std::string& text) {
  std::ofstream(path + ".tmp") << text;
  std::filesystem::rename(path + ".tmp", path);  // the server never sees half a file
}

double unauthenticated(const ServerProcess& server, const std::string& reason) {
  return client::valueOf(client::parsePrometheusText(client::httpGet(server.metricsUrl())),
                         "nidevo_unauthenticated_calls_total{reason=\"" + reason + "\"}");
}

TEST(Auth, EveryCallButHealthNeedsABearerTokenFromTheFile) {
  const std::string dir = makeTempDir(), tokens = dir + "/tokens";
  writeTokens(tokens, "# clients\nsecret-one\nsecret-two\n");
  ServerProcess server({"--token_file=" + tokens});
  EXPECT_TRUE(streamStatus(server, "secret-one").ok());
  EXPECT_TRUE(streamStatus(server, "secret-two").ok());
  const grpc::Status missing = streamStatus(server, "");
  EXPECT_EQ(missing.error_code(), grpc::StatusCode::UNAUTHENTICATED) << missing.error_message();
  const grpc::Status wrong = streamStatus(server, "secret-three");
  EXPECT_EQ(wrong.error_code(), grpc::StatusCode::UNAUTHENTICATED) << wrong.error_message();

  client::Client anonymous(optionsFor(server, ""));
  v1::ServerInfo info;
  EXPECT_EQ(anonymous.serverInfo(&info).error_code(), grpc::StatusCode::UNAUTHENTICATED);
  bool serving = false;
  EXPECT_TRUE(anonymous.health("", &serving).ok());  // probes carry no token
  EXPECT_TRUE(serving);
  client::Client known(optionsFor(server, "secret-one"));
  EXPECT_TRUE(known.serverInfo(&info).ok());

  EXPECT_EQ(unauthenticated(server, "missing"), 2);  // the stream and the server info
  EXPECT_EQ(unauthenticated(server, "wrong"), 1);
  const std::string log = server.log();
  for (const char* token : {"secret-one", "secret-two", "secret-three"})
    EXPECT_EQ(log.find(token), std::string::npos) << "a token in the log:\n" << log;
}

// The programs a user runs take the token from --token_file or NIDEVO_TOKEN_FILE: info, the load
// tester, replay, and the Python example.
TEST(Auth, ClientProgramsSendTheTokenOfTheirTokenFile) {
  const std::string dir = makeTempDir(), tokens = dir + "/tokens", mine = dir + "/mine";
  writeTokens(tokens, "secret-one\n");
  writeTokens(mine, "secret-one\n");
  ServerProcess server({"--token_file=" + tokens});
  const std::string client = NIDEVO_BIN_DIR "/nidevo-client ";
  const std::string at = " --target " + server.target();
  std::string out;
  EXPECT_NE(runCommand(client + "info" + at, &out), 0);
  EXPECT_NE(out.find("UNAUTHENTICATED"), std::string::npos) << out;
  EXPECT_EQ(runCommand(client + "info" + at + " --token_file " + mine, &out), 0) << out;
  EXPECT_EQ(runCommand("NIDEVO_TOKEN_FILE=" + mine + " " + client + "info" + at, &out), 0) << out;
  EXPECT_EQ(runCommand(client + "load" + at + " --token_file " + mine +
                           " --sessions 1 --warmup_s 0 --duration_s 1 --frames 5 --encoding raw",
                       &out),
            0)
      << out;
  EXPECT_NE(out.find("closed OK x1"), std::string::npos) << out;
  EXPECT_EQ(runCommand(client + "replay" + at + " --token_file " + mine +
                           " --frames 5 --encoding raw --out " + dir + "/poses.txt",
                       &out),
            0)
      << out;
  EXPECT_NE(out.find("5 answered"), std::string::npos) << out;

  // The Python example, when its gRPC packages are installed (the test command installs them).
  if (runCommand("/usr/bin/python3 -c 'import grpc_tools'", &out) == 0) {
    ASSERT_EQ(runCommand("/usr/bin/python3 -m grpc_tools.protoc -I" NIDEVO_SOURCE_DIR
                         "/proto --python_out=" +
                             dir + " --grpc_python_out=" + dir +
                             " " NIDEVO_SOURCE_DIR "/proto/nidevo/v1/odometry.proto",
                         &out),
              0)
        << out;
    const std::string folder = dir + "/office";
    ASSERT_EQ(runCommand(NIDEVO_BIN_DIR "/nidevo-synth --frames 5 --out " + folder, &out), 0)
        << out;
    const std::string python = "PYTHONPATH=" + dir +
                               " /usr/bin/python3 " NIDEVO_SOURCE_DIR
                               "/client/python/nidevo_stream.py" +
                               at + " --folder " + folder;
    EXPECT_NE(runCommand(python, &out), 0) << out;
    EXPECT_EQ(runCommand(python + " --token_file " + mine, &out), 0) << out;
  }
  EXPECT_EQ(unauthenticated(server, "wrong"), 0);
  std::filesystem::remove_all(dir);
}

TEST(Auth, SighupReloadsTheTokensWithoutDroppingOpenSessions) {
  const std::string dir = makeTempDir(), tokens = dir + "/tokens";
  writeTokens(tokens, "before\n");
  ServerProcess server({"--token_file=" + tokens});
  const TestSequence office = renderOffice(6, 1);
  const auto encoding = client::parseFrameEncoding("raw");
  client::Client client(optionsFor(server, "before"));
  std::vector<v1::TrackResponse> answers;
  std::mutex mutex;
  auto session = client.open(sessionFor(office.camera, encoding), [&](const v1::TrackResponse& r) {
    std::lock_guard<std::mutex> lock(mutex);
    answers.push_back(r);
  });
  v1::Frame frame;
  for (size_t i = 0; i < 3; ++i) {
    client::encodeFrame(office.frames[i], office.camera.depth_scale, encoding, &frame);
    frame.set_sequence(i);
    ASSERT_TRUE(session->send(frame));
  }
  // The call is admitted when the server starts it, not when the client opens it: only answers
  // prove the session was let in with the old token before the reload.
  const auto until = std::chrono::steady_clock::now() + 20s;
  const auto answered = [&] {
    std::lock_guard<std::mutex> lock(mutex);
    return answers.size();
  };
  while (answered() < 3 && std::chrono::steady_clock::now() < until)
    std::this_thread::sleep_for(20ms);
  ASSERT_EQ(answered(), 3u);
  writeTokens(tokens, "after\n");
  server.signal(SIGHUP);
  while (server.log().find("reloaded 1 tokens") == std::string::npos &&
         std::chrono::steady_clock::now() < until)
    std::this_thread::sleep_for(20ms);
  for (size_t i = 3; i < office.frames.size(); ++i) {  // the open session goes on
    client::encodeFrame(office.frames[i], office.camera.depth_scale, encoding, &frame);
    frame.set_sequence(i);
    ASSERT_TRUE(session->send(frame));
  }
  EXPECT_TRUE(session->finish().ok());
  EXPECT_EQ(answers.size(), office.frames.size());
  EXPECT_TRUE(streamStatus(server, "after").ok());
  EXPECT_EQ(streamStatus(server, "before").error_code(), grpc::StatusCode::UNAUTHENTICATED);

  writeTokens(tokens, "# nobody\n");  // a bad file: the server keeps what it had
  server.signal(SIGHUP);
  while (server.log().find("keeping the 1 tokens") == std::string::npos &&
         std::chrono::steady_clock::now() < until + 20s)
    std::this_thread::sleep_for(20ms);
  EXPECT_NE(server.log().find("holds no token; keeping the 1 tokens"), std::string::npos)
      << server.log();
  EXPECT_TRUE(streamStatus(server, "after").ok());
}

TEST(Auth, ATokenFileThatCannotBeReadStopsTheServerAtStart) {
  EXPECT_THROW(ServerProcess({"--token_file=/nonexistent/tokens"}), std::runtime_error);
}

// A CA, a server certificate and a client certificate it signs, and one it does not.
struct Pki {
  std::string dir;
  explicit Pki(const std::string& d) : dir(d) {
    const std::string conf = dir + "/san.cnf";
    std::ofstream(conf) << "subjectAltName=DNS:localhost,IP:127.0.0.1\n";
    const std::string commands[] = {
        "openssl req -x509 -newkey rsa:2048 -nodes -days 1 -subj /CN=nidevo-test-ca -keyout " +
            dir + "/ca.key -out " + dir + "/ca.pem",
        "openssl req -newkey rsa:2048 -nodes -subj /CN=localhost -keyout " + dir +
            "/server.key -out " + dir + "/server.csr",
        "openssl x509 -req -in " + dir + "/server.csr -CA " + dir + "/ca.pem -CAkey " + dir +
            "/ca.key -CAcreateserial -days 1 -extfile " + conf + " -out " + dir + "/server.pem",
        "openssl req -newkey rsa:2048 -nodes -subj /CN=client -keyout " + dir +
            "/client.key -out " + dir + "/client.csr",
        "openssl x509 -req -in " + dir + "/client.csr -CA " + dir + "/ca.pem -CAkey " + dir +
            "/ca.key -CAcreateserial -days 1 -out " + dir + "/client.pem",
        "openssl req -x509 -newkey rsa:2048 -nodes -days 1 -subj /CN=stranger -keyout " + dir +
            "/stranger.key -out " + dir + "/stranger.pem",
    };
    for (const std::string& c : commands) {
      std::string out;
      if (runCommand(c, &out) != 0) throw std::runtime_error(c + ": " + out);
    }
  }
};

TEST(Auth, MutualTlsAdmitsOnlyClientsWithACertificateFromTheCa) {
  const Pki pki(makeTempDir());
  const std::string d = pki.dir;
  ServerProcess server({"--tls_cert_file=" + d + "/server.pem",
                        "--tls_key_file=" + d + "/server.key",
                        "--tls_client_ca_file=" + d + "/ca.pem"});
  client::ChannelOptions options = optionsFor(server, "");
  options.tls = true;
  options.ca_file = d + "/ca.pem";
  options.connect_timeout_s = 3;
  bool serving = false;
  {
    client::ChannelOptions with_cert = options;
    with_cert.cert_file = d + "/client.pem";
    with_cert.key_file = d + "/client.key";
    client::Client client(with_cert);
    EXPECT_TRUE(client.health("", &serving).ok());
    const StreamResult result =
        streamSequence(client, renderOffice(2, 1), client::parseFrameEncoding("raw"));
    EXPECT_TRUE(result.status.ok()) << result.status.error_message();
  }
  {
    client::Client no_cert(options);
    EXPECT_FALSE(no_cert.health("", &serving).ok());
  }
  {
    client::ChannelOptions stranger = options;
    stranger.cert_file = d + "/stranger.pem";
    stranger.key_file = d + "/stranger.key";
    client::Client client(stranger);
    EXPECT_FALSE(client.health("", &serving).ok());
  }
}

}  // namespace
}  // namespace nidevo::test
