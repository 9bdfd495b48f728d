#include "common/live_server.h"

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <random>

#include <civetweb.h>
#include <dlfcn.h>
#include <pthread.h>

#include "common/scene.h"

// Debian's civetweb (1.15) gives each of its threads a 100 KiB stack
// (USE_STACK_SIZE), and glibc takes the threads' static TLS out of that stack:
// in a lab executable OpenBLAS's 60 KiB and METIS's 28 KiB of TLS (CHOLMOD's,
// common/sparse.h) leave civetweb's threads 12 KiB, and the first request
// overflowed it (a crash in getnameinfo). This definition, which the program
// exports in place of libc's, raises every stack size asked for to 1 MiB at
// least; libc's own does the rest.
extern "C" int pthread_attr_setstacksize(pthread_attr_t* attributes, std::size_t size) {
  using Function = int (*)(pthread_attr_t*, std::size_t);
  static const Function libc_own = reinterpret_cast<Function>(dlsym(RTLD_NEXT, "pthread_attr_setstacksize"));
  return libc_own(attributes, std::max<std::size_t>(size, std::size_t{1} << 20));
}

namespace cl {

struct LiveServer::Wake {
  std::condition_variable ready;
};

namespace {

LiveServer* server_of(const mg_connection* connection) {
  return static_cast<LiveServer*>(mg_get_user_data(mg_get_context(connection)));
}

int request_trampoline(mg_connection* connection, void*) { return server_of(connection)->on_request(connection); }
int connect_trampoline(const mg_connection* connection, void*) { return server_of(connection)->on_connect(connection); }
void ready_trampoline(mg_connection* connection, void*) { server_of(connection)->on_ready(connection); }
int data_trampoline(mg_connection* connection, int bits, char* data, std::size_t length, void*) {
  return server_of(connection)->on_data(connection, bits, data, length);
}
void close_trampoline(const mg_connection* connection, void*) { server_of(connection)->on_close(connection); }

// civetweb's own complaints (a bad request line, say) stay out of the terminal:
// a refusal of ours is one line, printed by refuse_line.
int quiet_log(const mg_connection*, const char*) { return 1; }

}  // namespace

std::string live_token() {
  std::random_device device;
  std::string token;
  static const char* digits = "0123456789abcdef";
  for (int word = 0; word < 4; ++word) {
    std::uint32_t bits = device();
    for (int d = 0; d < 8; ++d, bits >>= 4) token += digits[bits & 15u];
  }
  return token;
}

bool live_origin_allowed(const char* origin, int port) {
  if (origin == nullptr) return true;
  const std::string given(origin);
  const std::string tail = ":" + std::to_string(port);
  return given == "http://127.0.0.1" + tail || given == "http://localhost" + tail;
}

bool live_token_matches(const char* query, const std::string& token) {
  if (query == nullptr || token.empty()) return false;
  const std::string text(query);
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t end = std::min(text.find('&', start), text.size());
    if (text.compare(start, end - start, "token=" + token) == 0 && end - start == token.size() + 6) return true;
    start = end + 1;
  }
  return false;
}

LiveServer::LiveServer(int port, std::string page)
    : page_(std::move(page)), token_(live_token()), wake_(std::make_unique<Wake>()) {
  mg_init_library(0);
  const std::string listen = "127.0.0.1:" + std::to_string(port);
  const char* options[] = {"listening_ports", listen.c_str(), "num_threads", "8", "websocket_timeout_ms", "3600000",
                           "request_timeout_ms", "10000",
                           // A frame is two writes (its status, then its data): with Nagle's algorithm
                           // the second waited for the page's delayed ACK, 40 ms, and a 32² curtain
                           // stepping 900 times a second reached the page 46 times a second.
                           "tcp_nodelay", "1", nullptr};
  mg_callbacks callbacks{};
  callbacks.log_message = quiet_log;
  context_ = mg_start(&callbacks, this, options);
  if (context_ == nullptr) {
    mg_exit_library();
    throw InputError("--live: cannot listen on 127.0.0.1:" + std::to_string(port) + " (in use?)");
  }
  mg_server_port ports[4];
  const int count = mg_get_server_ports(context_, 4, ports);
  port_ = count > 0 ? ports[0].port : port;
  mg_set_request_handler(context_, "/", request_trampoline, nullptr);
  mg_set_websocket_handler(context_, "/ws", connect_trampoline, ready_trampoline, data_trampoline, close_trampoline,
                           nullptr);
}

LiveServer::~LiveServer() {
  mg_stop(context_);
  mg_exit_library();
}

std::string LiveServer::url() const {
  return "http://127.0.0.1:" + std::to_string(port_) + "/?token=" + token_;
}

bool LiveServer::token_ok(const char* query) const { return live_token_matches(query, token_); }

void LiveServer::refuse_line(const std::string& line) { std::fprintf(stderr, "%s\n", line.c_str()); }

int LiveServer::on_request(mg_connection* connection) {
  const mg_request_info* request = mg_get_request_info(connection);
  if (std::strcmp(request->local_uri, "/") != 0) {
    mg_send_http_error(connection, 404, "%s", "live: not found (the page is /?token=...)");
    return 404;
  }
  if (!token_ok(request->query_string)) {
    refuse_line("live: a request for the page without the run's token, refused");
    mg_send_http_error(connection, 403, "%s", "live: wrong or missing token (open the URL the program printed)");
    return 403;
  }
  mg_printf(connection,
            "HTTP/1.1 200 OK\r\nContent-Type: text/html; charset=utf-8\r\nContent-Length: %zu\r\n"
            "Cache-Control: no-store\r\nConnection: close\r\n\r\n",
            page_.size());
  mg_write(connection, page_.data(), page_.size());
  return 200;
}

int LiveServer::on_connect(const mg_connection* connection) {
  const mg_request_info* request = mg_get_request_info(connection);
  if (!token_ok(request->query_string)) {
    refuse_line("live: a WebSocket without the run's token, refused");
    return 1;
  }
  const char* origin = mg_get_header(connection, "Origin");
  if (!live_origin_allowed(origin, port_)) {
    refuse_line("live: a WebSocket from the foreign Origin '" + std::string(origin).substr(0, 80) + "', refused");
    return 1;
  }
  return 0;
}

void LiveServer::on_ready(mg_connection* connection) {
  int id = 0;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    id = next_client_++;
    clients_[id] = Client{connection, 0};
    ids_[connection] = id;
  }
  push(LiveInbound{id, {}, false, true});
}

int LiveServer::on_data(mg_connection* connection, int bits, char* data, std::size_t length) {
  const int opcode = bits & 0xf;
  if (opcode == MG_WEBSOCKET_OPCODE_CONNECTION_CLOSE) return 0;
  if (opcode != MG_WEBSOCKET_OPCODE_TEXT && opcode != MG_WEBSOCKET_OPCODE_BINARY) return 1;
  int id = 0;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    const auto found = ids_.find(connection);
    if (found == ids_.end()) return 1;
    id = found->second;
  }
  // A message over the cap is kept to its first cap + 1 bytes: the parser refuses it by its size.
  push(LiveInbound{id, std::string(data, std::min(length, kLiveInboundCap)), false, false});
  return 1;
}

void LiveServer::on_close(const mg_connection* connection) {
  int id = 0;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    const auto found = ids_.find(connection);
    if (found == ids_.end()) return;
    id = found->second;
    clients_.erase(id);
    ids_.erase(found);
  }
  push(LiveInbound{id, {}, true, false});
}

void LiveServer::push(LiveInbound inbound) {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (inbound_.size() >= kInboundQueueCap && !inbound.closed) {
      // A client that floods the queue loses its newest messages; the loop drains it every few ms.
      return;
    }
    inbound_.push_back(std::move(inbound));
  }
  wake_->ready.notify_one();
}

std::vector<LiveInbound> LiveServer::take_inbound() {
  const std::lock_guard<std::mutex> lock(mutex_);
  std::vector<LiveInbound> taken(std::make_move_iterator(inbound_.begin()), std::make_move_iterator(inbound_.end()));
  inbound_.clear();
  return taken;
}

void LiveServer::wait_inbound(double seconds) {
  std::unique_lock<std::mutex> lock(mutex_);
  if (!inbound_.empty() || seconds <= 0.0) return;
  wake_->ready.wait_for(lock, std::chrono::duration<double>(seconds));
}

void LiveServer::send_text(int client, const std::string& text) {
  const std::lock_guard<std::mutex> lock(mutex_);
  for (auto& [id, entry] : clients_) {
    if (client >= 0 && id != client) continue;
    mg_lock_connection(entry.connection);
    mg_websocket_write(entry.connection, MG_WEBSOCKET_OPCODE_TEXT, text.data(), text.size());
    mg_unlock_connection(entry.connection);
  }
}

std::vector<int> LiveServer::ready_clients() {
  const std::lock_guard<std::mutex> lock(mutex_);
  std::vector<int> ready;
  for (const auto& [id, entry] : clients_) {
    if (entry.in_flight < kFramesInFlight) ready.push_back(id);
  }
  return ready;
}

void LiveServer::send_frame(int client, const std::string& text, const std::vector<float>& frame) {
  const std::lock_guard<std::mutex> lock(mutex_);
  const auto found = clients_.find(client);
  if (found == clients_.end()) return;
  mg_connection* connection = found->second.connection;
  mg_lock_connection(connection);
  mg_websocket_write(connection, MG_WEBSOCKET_OPCODE_TEXT, text.data(), text.size());
  mg_websocket_write(connection, MG_WEBSOCKET_OPCODE_BINARY, reinterpret_cast<const char*>(frame.data()),
                     frame.size() * sizeof(float));
  mg_unlock_connection(connection);
  ++found->second.in_flight;
}

void LiveServer::acknowledge(int client) {
  const std::lock_guard<std::mutex> lock(mutex_);
  const auto found = clients_.find(client);
  if (found != clients_.end() && found->second.in_flight > 0) --found->second.in_flight;
}

int LiveServer::clients() {
  const std::lock_guard<std::mutex> lock(mutex_);
  return static_cast<int>(clients_.size());
}

}  // namespace cl
