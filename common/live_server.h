#pragma once
// The live mode's server (docs/DESIGN.md §3, "The live mode", says where each
// limit lives): Boost.Beast over Asio, one io_context thread, on 127.0.0.1
// only. Beast owns HTTP and RFC 6455; this is the course's policy. GET
// /?token=T serves the page, /ws?token=T is its WebSocket; a wrong token, Host
// or Origin is refused (403), as are a header read twice or a folded line
// (400), a head over kRequestCap (431) and more than kNewSocketsPerSecond new
// WebSockets a second (503). The live loop (common/live.h) never touches a
// socket: it fills per-client outboxes, where the newest frame replaces the
// one waiting; a client that takes nothing for kStalledSeconds, or has over
// kOutboxBytes waiting (its frame aside), is dropped; its messages wait in a
// queue of kInboundPerClient, and while that is full it is not read (TCP
// holds the rest, none is lost).
#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "common/live_protocol.h"

namespace cl {

// A message from a client, or the news that it came (opened) or went away (closed).
struct LiveInbound {
  int client = 0;
  std::string text;
  bool closed = false;
  bool opened = false;
};

class LiveServer {
 public:
  // Listens on 127.0.0.1:port (0: a free port), serves `page` (HTML) at "/"
  // and watches SIGINT and SIGTERM (stop_requested). Throws InputError when it
  // cannot listen (the port in use).
  LiveServer(int port, std::string page);
  ~LiveServer();  // closes every connection and stops the server's thread
  LiveServer(const LiveServer&) = delete;
  LiveServer& operator=(const LiveServer&) = delete;

  int port() const { return port_; }
  const std::string& token() const { return token_; }
  std::string url() const;  // http://127.0.0.1:PORT/?token=T

  // The messages, openings and closings since the last call: at most
  // kTakePerClient of each client's and kTakePerTurn in all, the clients in
  // turn, each client's in order. The opening of a client that has gone
  // already is left out (its closing is not).
  std::vector<LiveInbound> take_inbound();
  // Waits up to `seconds` for an inbound message or a stop (returns at once if one is there).
  void wait_inbound(double seconds);
  // Whether SIGINT or SIGTERM came.
  bool stop_requested() const;

  // A text message to one client (client < 0: to every client). Never blocks.
  void send_text(int client, const std::string& text);
  // The clients ready for a frame: fewer than kFramesInFlight frames sent and
  // not acknowledged ({"cmd": "ack"}, acknowledge()).
  std::vector<int> ready_clients();
  // A frame (its status text, then its binary data) to `client`, counted as in
  // flight; replaces a frame of the client's still waiting. Never blocks.
  void send_frame(int client, const std::string& text, const std::vector<float>& frame);
  void acknowledge(int client);
  int clients();

  static constexpr int kFramesInFlight = 2;
  static constexpr int kMaxClients = 16;
  static constexpr int kMaxPending = 32;
  static constexpr int kNewSocketsPerSecond = 50;
  static constexpr double kRequestSeconds = 3.0;
  static constexpr std::size_t kRequestCap = 8192;  // bytes of a request's head
  static constexpr std::size_t kInboundPerClient = 64;
  static constexpr std::size_t kTakePerClient = 32;
  static constexpr std::size_t kTakePerTurn = 256;
  static constexpr std::size_t kOutboxBytes = std::size_t{1} << 20;
  static constexpr std::size_t kSendBufferBytes = std::size_t{256} << 10;  // the kernel's queue of a WebSocket
  static constexpr double kStalledSeconds = 5.0;
  static constexpr double kSilentSeconds = 20.0;  // Beast's idle timeout: pinged at half, closed at the end

  struct State;  // the queues both threads share, and the server thread's own (live_server.cpp)

 private:
  std::string token_;
  int port_ = 0;
  std::unique_ptr<State> state_;
};

// 128 random bits as 32 hex digits (std::random_device).
std::string live_token();

// The host name a GitHub Codespace forwards `port` under, NAME-PORT.DOMAIN,
// from its CODESPACE_NAME and GITHUB_CODESPACES_PORT_FORWARDING_DOMAIN; "" when
// either is missing (not in a codespace). The page reached through it is
// served too (the token still guards it): the dev container's live page.
std::string live_forwarded_host(int port, const char* codespace, const char* domain);

// Whether `origin` (the WebSocket's Origin header, every byte of it; none:
// not given) may connect to a server on `port`: none (a client that is not a
// browser), http://127.0.0.1:PORT or http://localhost:PORT exactly, or in a
// codespace https:// and the name it forwards the port under.
bool live_origin_allowed(const std::optional<std::string>& origin, int port);

// Whether `host` (a request's Host header) names this server on `port`:
// 127.0.0.1:PORT or localhost:PORT (either without the port when it is 80),
// or in a codespace the name it forwards the port under (live_forwarded_host).
// A page of another name that resolves to 127.0.0.1 (DNS rebinding) is refused.
bool live_host_allowed(const std::string& host, int port);

// Whether `query` (a request's query string, every byte of it; none: not
// given) carries token=`token`.
bool live_token_matches(const std::optional<std::string>& query, const std::string& token);

// Whether a request's head (its bytes up to the blank line) folds a header
// line (obs-fold, RFC 7230 §3.2.4: a line that starts with a space or a tab),
// which the server refuses (400) where Beast would join the lines.
bool live_head_folded(const std::string& head);

// One line to stderr, at most kLiveLogPerSecond a second from the whole
// program: the rest are counted, and live_log_flush() (or the next line once
// the second is over) prints "live: N more lines like these ... not shown".
constexpr int kLiveLogPerSecond = 10;
void live_log(const std::string& line);
void live_log_flush(bool final = false);  // final: the summary now, whatever the time

}  // namespace cl
