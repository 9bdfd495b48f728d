// The live server's policy (common/live_server.h): who may connect. Beast
// owns the wire (HTTP parsing, RFC 6455 framing, close codes, UTF-8), so what
// is tested here is the course's own: the run's token, its Origin and Host,
// every byte of each compared, and the folded header lines it refuses.
#include "tests/support/catch.h"

#include <optional>
#include <string>

#include "common/live_server.h"

TEST_CASE("live server accepts only the run's token, its own Origin and its own Host", "[live]") {
  const std::string token = cl::live_token();
  CHECK(token.size() == 32);
  CHECK(token != cl::live_token());  // 128 random bits: two draws differ
  CHECK(cl::live_token_matches(("token=" + token).c_str(), token));
  CHECK(cl::live_token_matches(("a=1&token=" + token + "&b=2").c_str(), token));
  CHECK_FALSE(cl::live_token_matches(std::nullopt, token));
  CHECK_FALSE(cl::live_token_matches(std::string("token=" + token + '\0' + "x"), token));  // every byte counts
  CHECK_FALSE(cl::live_token_matches("", token));
  CHECK_FALSE(cl::live_token_matches(("token=" + token + "x").c_str(), token));
  CHECK_FALSE(cl::live_token_matches(("token=" + token.substr(1)).c_str(), token));
  CHECK_FALSE(cl::live_token_matches(("xtoken=" + token).c_str(), token));
  CHECK_FALSE(cl::live_token_matches("token=", ""));
  CHECK(cl::live_origin_allowed(std::nullopt, 8123));
  CHECK(cl::live_origin_allowed("http://127.0.0.1:8123", 8123));
  CHECK(cl::live_origin_allowed("http://localhost:8123", 8123));
  CHECK_FALSE(cl::live_origin_allowed("http://127.0.0.1:8124", 8123));
  CHECK_FALSE(cl::live_origin_allowed("http://evil.example", 8123));
  CHECK_FALSE(cl::live_origin_allowed("http://127.0.0.1:8123.evil.example", 8123));
  CHECK_FALSE(cl::live_origin_allowed("null", 8123));
  CHECK_FALSE(cl::live_origin_allowed(std::string("http://127.0.0.1:8123\0.evil.example", 35), 8123));  // every byte counts
  CHECK(cl::live_host_allowed("127.0.0.1:8123", 8123));
  CHECK(cl::live_host_allowed("localhost:8123", 8123));
  CHECK_FALSE(cl::live_host_allowed("evil.example:8123", 8123));  // DNS rebinding: another name on 127.0.0.1
  CHECK_FALSE(cl::live_host_allowed("127.0.0.1", 8123));
  CHECK_FALSE(cl::live_host_allowed("127.0.0.1:81234", 8123));
  CHECK(cl::live_host_allowed("localhost", 80));
}

TEST_CASE("live server names the host a codespace forwards its port under, and only there", "[live]") {
  CHECK(cl::live_forwarded_host(8765, "fuzzy-space-abc123", "app.github.dev") == "fuzzy-space-abc123-8765.app.github.dev");
  CHECK(cl::live_forwarded_host(8765, nullptr, "app.github.dev").empty());  // not in a codespace
  CHECK(cl::live_forwarded_host(8765, "fuzzy-space-abc123", nullptr).empty());
  CHECK(cl::live_forwarded_host(8765, "", "app.github.dev").empty());
  // Outside a codespace (this test's environment has neither variable) no such name is let in.
  CHECK_FALSE(cl::live_host_allowed("fuzzy-space-abc123-8765.app.github.dev", 8765));
  CHECK_FALSE(cl::live_origin_allowed("https://fuzzy-space-abc123-8765.app.github.dev", 8765));
}

TEST_CASE("live server finds a folded header line wherever it is", "[live]") {
  CHECK(cl::live_head_folded("GET / HTTP/1.1\r\nHost: 127.0.0.1:8123\r\n x\r\n\r\n"));
  CHECK(cl::live_head_folded("GET / HTTP/1.1\r\nX-A: a\r\n\tb\r\nHost: 127.0.0.1:8123\r\n\r\n"));
  CHECK_FALSE(cl::live_head_folded("GET / HTTP/1.1\r\nHost: 127.0.0.1:8123\r\nX-A: a b\r\n\r\n"));
  CHECK_FALSE(cl::live_head_folded("GET / HTTP/1.1\r\nHost:\t127.0.0.1:8123\r\n\r\n"));
}

