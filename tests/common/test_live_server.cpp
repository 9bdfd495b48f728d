// The live server's wire format (common/live_server.h): the WebSocket
// handshake's accept key (RFC 6455's own example), frame headers read as
// declared before any payload (so a frame is refused by its length), and the
// frames the server writes read back by the same parser.
#include "tests/support/catch.h"

#include <string>

#include "common/live_server.h"

TEST_CASE("live server's accept key is RFC 6455's example", "[live]") {
  CHECK(cl::websocket_accept("dGhlIHNhbXBsZSBub25jZQ==") == "s3pPLMBiTxaQ9kYGzzhZRbK+xOo=");
}

TEST_CASE("live server reads a frame's declared length from its header alone", "[live]") {
  // A masked text frame declaring 100 MiB (the 64-bit length form): complete with 14 bytes, no payload.
  const std::string big = std::string("\x81\xff\0\0\0\0\x06\x40\0\0", 10) + std::string("\x01\x02\x03\x04", 4);
  for (std::size_t have = 0; have < big.size(); ++have) {
    CAPTURE(have);
    CHECK_FALSE(cl::parse_websocket_header(big.data(), have).complete);
  }
  const cl::WebSocketHeader header = cl::parse_websocket_header(big.data(), big.size());
  REQUIRE(header.complete);
  CHECK_FALSE(header.bad);
  CHECK(header.fin);
  CHECK(header.opcode == 1);
  CHECK(header.masked);
  CHECK(header.length == (std::uint64_t{100} << 20));
  CHECK(header.size == 14);
  CHECK(header.mask[3] == 4);
}

TEST_CASE("live server's frames read back with their opcode and length at every length form", "[live]") {
  for (const std::size_t size : {std::size_t{0}, std::size_t{125}, std::size_t{126}, std::size_t{65535}, std::size_t{65536}}) {
    CAPTURE(size);
    const std::string payload(size, 'x');
    const std::string frame = cl::websocket_frame(2, payload.data(), payload.size());
    const cl::WebSocketHeader header = cl::parse_websocket_header(frame.data(), frame.size());
    REQUIRE(header.complete);
    CHECK(header.opcode == 2);
    CHECK_FALSE(header.masked);
    CHECK(header.length == size);
    CHECK(header.size + size == frame.size());
  }
}

TEST_CASE("live server marks the frames no client may send as bad", "[live]") {
  auto bad = [](const std::string& bytes) { return cl::parse_websocket_header(bytes.data(), bytes.size()).bad; };
  CHECK(bad(std::string("\xc1\x80\0\0\0\0", 6)));                        // a reserved bit set
  CHECK(bad(std::string("\x09\x80\0\0\0\0", 6)));                        // a ping not final
  CHECK(bad(std::string("\x89\xfe\0\x7e\0\0\0\0", 8)));                  // a ping of 126 bytes
  CHECK(bad(std::string("\x83\x80\0\0\0\0", 6)));                        // opcode 3, reserved
  CHECK(bad(std::string("\x81\xff\x80\0\0\0\0\0\0\0\0\0\0\0", 14)));    // a length with its top bit set
  CHECK_FALSE(bad(std::string("\x01\x80\0\0\0\0", 6)));                  // a text message's first fragment
  CHECK_FALSE(bad(std::string("\x80\x80\0\0\0\0", 6)));                  // its last
}
