#include "server_config.hpp"

#include <gtest/gtest.h>

namespace nidevo::server {
namespace {

TEST(ServerConfig, DefaultsAreValid) {
  ServerConfig c;
  c.workers = 2;  // 0 (one per core) is resolved by main before validation
  EXPECT_EQ(c.validate(), "");
}

// Each bad setting is refused with a message that starts with its name.
TEST(ServerConfig, EachBadSettingIsNamed) {
  struct Case {
    const char* field;
    void (*spoil)(ServerConfig*);
  };
  const Case cases[] = {
      {"workers", [](ServerConfig* c) { c->workers = 0; }},
      {"max_sessions", [](ServerConfig* c) { c->max_sessions = 0; }},
      {"max_message_bytes", [](ServerConfig* c) { c->max_message_bytes = 10; }},
      {"max_queue_capacity", [](ServerConfig* c) { c->max_queue_capacity = 1; }},
      {"idle_timeout_s", [](ServerConfig* c) { c->idle_timeout_s = 0; }},
      {"http2_stream_window_bytes", [](ServerConfig* c) { c->http2_stream_window_bytes = 1000; }},
      {"http2_stream_window_bytes", [](ServerConfig* c) { c->http2_stream_window_bytes = -1; }},
      {"http2_max_frame_bytes", [](ServerConfig* c) { c->http2_max_frame_bytes = 100; }},
      {"http2_max_frame_bytes", [](ServerConfig* c) { c->http2_max_frame_bytes = 1 << 24; }},
  };
  for (const Case& k : cases) {
    ServerConfig c;
    c.workers = 2;
    k.spoil(&c);
    EXPECT_EQ(c.validate().rfind(k.field, 0), 0u) << k.field << ": " << c.validate();
  }
}

TEST(ServerConfig, Http2SettingsAcceptGrpcsDefaultAndTheProtocolsRange) {
  ServerConfig c;
  c.workers = 2;
  for (int window : {0, 65535, 8 << 20, 1 << 30}) {
    c.http2_stream_window_bytes = window;
    EXPECT_EQ(c.validate(), "") << window;
  }
  for (int frame : {0, 16384, 1 << 20, 16777215}) {
    c.http2_max_frame_bytes = frame;
    EXPECT_EQ(c.validate(), "") << frame;
  }
}

}  // namespace
}  // namespace nidevo::server
