#pragma once
// The live mode's server (docs/DESIGN.md §3, "The live mode"): civetweb's
// HTTP and WebSocket server on 127.0.0.1 only. GET /?token=T serves the page,
// /ws?token=T is the page's WebSocket; neither answers without the run's
// token, and a WebSocket whose Origin is not this server's is refused. The
// live loop (common/live.h) reads the messages in its own thread; civetweb's
// threads only queue them.
#include <cstddef>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "common/live_protocol.h"

struct mg_context;
struct mg_connection;

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
  // Listens on 127.0.0.1:port (0: a free port) and serves `page` (HTML) at
  // "/". Throws InputError when it cannot listen (the port in use).
  LiveServer(int port, std::string page);
  ~LiveServer();  // closes every connection and stops civetweb's threads
  LiveServer(const LiveServer&) = delete;
  LiveServer& operator=(const LiveServer&) = delete;

  int port() const { return port_; }
  const std::string& token() const { return token_; }
  std::string url() const;  // http://127.0.0.1:PORT/?token=T

  // The messages and closings since the last call, oldest first.
  std::vector<LiveInbound> take_inbound();
  // Waits up to `seconds` for an inbound message (returns at once if one is queued).
  void wait_inbound(double seconds);

  // A text message to one client (client < 0: to every client).
  void send_text(int client, const std::string& text);
  // The clients ready for a frame: fewer than kFramesInFlight frames sent and
  // not acknowledged ({"cmd": "ack"}, acknowledge()).
  std::vector<int> ready_clients();
  // A binary message (a frame) to `client`, counted as in flight.
  void send_frame(int client, const std::string& text, const std::vector<float>& frame);
  void acknowledge(int client);
  int clients();

  static constexpr int kFramesInFlight = 2;
  static constexpr std::size_t kLiveInboundCap = kLiveMessageCap + 1;  // enough to refuse by size
  static constexpr std::size_t kInboundQueueCap = 1024;  // messages waiting for the loop

  // civetweb's callbacks (public for the C trampolines in live_server.cpp).
  int on_request(mg_connection* connection);
  int on_connect(const mg_connection* connection);
  void on_ready(mg_connection* connection);
  int on_data(mg_connection* connection, int bits, char* data, std::size_t length);
  void on_close(const mg_connection* connection);

 private:
  struct Client {
    mg_connection* connection;
    int in_flight = 0;
  };
  bool token_ok(const char* query) const;
  void refuse_line(const std::string& line);
  void push(LiveInbound inbound);

  std::string page_;
  std::string token_;
  int port_ = 0;
  mg_context* context_ = nullptr;
  std::mutex mutex_;  // clients_, inbound_, next_client_
  std::map<int, Client> clients_;
  std::map<const mg_connection*, int> ids_;
  std::deque<LiveInbound> inbound_;
  int next_client_ = 1;
  struct Wake;
  std::unique_ptr<Wake> wake_;
};

// 128 random bits as 32 hex digits (std::random_device).
std::string live_token();

// Whether `origin` (the WebSocket's Origin header; null: none given) may
// connect to a server on `port`: none (a client that is not a browser), or
// http://127.0.0.1:PORT or http://localhost:PORT exactly.
bool live_origin_allowed(const char* origin, int port);

// Whether `query` (a request's query string; null: none) carries token=`token`.
bool live_token_matches(const char* query, const std::string& token);

}  // namespace cl
