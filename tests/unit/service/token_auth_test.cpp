#include "token_auth.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <string>

namespace nidevo::server {
namespace {

using Result = TokenAuthenticator::Result;

std::string writeFile(const std::string& name, const std::string& text) {
  const std::string path = testing::TempDir() + "/" + name;
  std::ofstream(path) << text;
  return path;
}

std::string bearer(const std::string& token) { return "Bearer " + token; }

TEST(TokenAuth, AcceptsEveryTokenOfTheFileAndNothingElse) {
  const TokenAuthenticator auth(
      writeFile("tokens_a", "# two clients\nalpha-123\n\n  beta-456  # trailing comment\n"));
  EXPECT_TRUE(auth.enabled());
  EXPECT_EQ(auth.size(), 2u);
  for (const char* good : {"alpha-123", "beta-456"}) {
    const std::string header = bearer(good);
    EXPECT_EQ(auth.checkHeader(&header), Result::kOk) << good;
  }
  for (const char* bad : {"alpha-12", "alpha-1234", "ALPHA-123", "", "# two clients"}) {
    const std::string header = bearer(bad);
    EXPECT_EQ(auth.checkHeader(&header), Result::kWrong) << bad;
  }
  EXPECT_EQ(auth.checkHeader(nullptr), Result::kMissing);
  const std::string basic = "Basic alpha-123", bare = "alpha-123";
  EXPECT_EQ(auth.checkHeader(&basic), Result::kMissing);
  EXPECT_EQ(auth.checkHeader(&bare), Result::kMissing);
}

TEST(TokenAuth, OffLetsEveryCallThrough) {
  const TokenAuthenticator auth;
  EXPECT_FALSE(auth.enabled());
  EXPECT_EQ(auth.checkHeader(nullptr), Result::kOk);
}

TEST(TokenAuth, KeepsOnlyDigestsOfTheTokens) {
  // SHA-256("abc"), FIPS 180-2's example: the stored form, never the token itself.
  const auto d = TokenAuthenticator::digest("abc");
  EXPECT_EQ(d[0], 0xba);
  EXPECT_EQ(d[1], 0x78);
  EXPECT_EQ(d[31], 0xad);
}

TEST(TokenAuth, BadFilesNameTheFileAndLine) {
  EXPECT_THROW(TokenAuthenticator("/nonexistent/tokens"), std::runtime_error);
  try {
    TokenAuthenticator auth(writeFile("tokens_empty", "# nothing\n\n"));
    FAIL() << "an empty token file was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("holds no token"), std::string::npos) << e.what();
  }
  try {
    TokenAuthenticator auth(writeFile("tokens_blank", "good\ntwo words\n"));
    FAIL() << "a token with a blank was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("tokens_blank:2"), std::string::npos) << e.what();
  }
}

TEST(TokenAuth, ReloadSwapsTheTokensAndAFailedReloadKeepsTheOldOnes) {
  const std::string path = writeFile("tokens_reload", "old-token\n");
  TokenAuthenticator auth(path);
  const std::string old_header = bearer("old-token"), new_header = bearer("new-token");
  writeFile("tokens_reload", "new-token\n");
  EXPECT_EQ(auth.reload(), "");
  EXPECT_EQ(auth.checkHeader(&new_header), Result::kOk);
  EXPECT_EQ(auth.checkHeader(&old_header), Result::kWrong);
  writeFile("tokens_reload", "\n");
  EXPECT_NE(auth.reload().find("holds no token"), std::string::npos);
  EXPECT_EQ(auth.checkHeader(&new_header), Result::kOk);
}

}  // namespace
}  // namespace nidevo::server
