#include "common/live_server.h"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <condition_variable>
#include <csignal>
#include <cstdio>
#include <deque>
#include <list>
#include <map>
#include <mutex>
#include <random>
#include <set>
#include <thread>

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <nlohmann/json.hpp>

#include "common/scene.h"

namespace cl {

namespace net = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = net::ip::tcp;
using beast::error_code;

namespace {

using Clock = std::chrono::steady_clock;

double since(Clock::time_point then, Clock::time_point now) { return std::chrono::duration<double>(now - then).count(); }

std::chrono::milliseconds millis(double seconds) { return std::chrono::milliseconds(static_cast<long>(seconds * 1000.0)); }

std::string lower(std::string text) {
  for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

// A header's value as a stderr line may show it: at most 80 bytes, printable ASCII ('?' for the rest).
std::string shown(beast::string_view text) {
  std::string out(text.data(), std::min<std::size_t>(text.size(), 80));
  for (char& c : out) c = static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f ? '?' : c;
  return out;
}

std::string error_message(const std::string& line) { return live_json_text(nlohmann::json{{"type", "error"}, {"text", line}}); }

struct LogState {
  std::mutex mutex;
  Clock::time_point window = Clock::now();
  int printed = 0;
  long hidden = 0;
};
LogState& log_state() {
  static LogState state;
  return state;
}

void log_roll(LogState& state, Clock::time_point now, bool final = false) {  // with state.mutex held
  if (since(state.window, now) < 1.0 && !final) return;
  if (state.hidden > 0) {
    std::fprintf(stderr, "live: %ld more lines like these in the last %.0f s, not shown\n", state.hidden,
                 std::max(1.0, since(state.window, now)));
  }
  state.window = now;
  state.printed = 0;
  state.hidden = 0;
}

}  // namespace

void live_log(const std::string& line) {
  LogState& state = log_state();
  const std::lock_guard<std::mutex> lock(state.mutex);
  log_roll(state, Clock::now());
  if (state.printed < kLiveLogPerSecond) {
    ++state.printed;
    std::fprintf(stderr, "%s\n", line.c_str());
  } else {
    ++state.hidden;
  }
}

void live_log_flush(bool final) {
  LogState& state = log_state();
  const std::lock_guard<std::mutex> lock(state.mutex);
  log_roll(state, Clock::now(), final);
}

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

bool live_origin_allowed(const std::optional<std::string>& origin, int port) {
  if (!origin) return true;
  const std::string tail = ":" + std::to_string(port);
  return *origin == "http://127.0.0.1" + tail || *origin == "http://localhost" + tail;
}

bool live_host_allowed(const std::string& host, int port) {
  const std::string tail = ":" + std::to_string(port);
  return host == "127.0.0.1" + tail || host == "localhost" + tail || (port == 80 && (host == "127.0.0.1" || host == "localhost"));
}

bool live_token_matches(const std::optional<std::string>& query, const std::string& token) {
  if (!query || token.empty()) return false;
  const std::string& text = *query;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t end = std::min(text.find('&', start), text.size());
    if (text.compare(start, end - start, "token=" + token) == 0 && end - start == token.size() + 6) return true;
    start = end + 1;
  }
  return false;
}

bool live_head_folded(const std::string& head) {
  return head.find("\r\n ") != std::string::npos || head.find("\r\n\t") != std::string::npos;
}

// What the live loop and the server's thread share, under `mutex`.
struct LiveServer::Shared {
  struct Client {
    std::deque<LiveInbound> inbound;  // ends with the closing once the client has gone
    bool gone = false;
    bool unread = false;              // its queue was full: the server stopped reading it
    std::deque<std::string> texts;    // waiting for the socket
    std::size_t text_bytes = 0;
    std::string status, data;         // the newest frame (its status and positions), empty when none waits
    bool frame = false;
    int in_flight = 0;
  };
  std::mutex mutex;
  std::condition_variable inbound_ready;
  std::map<int, Client> clients;
  int last_taken = 0;  // take_inbound starts after this client: every client gets its turn
  std::atomic<bool> stop{false};
};

// The server's thread: the io_context and what only its handlers touch.
struct LiveServer::Io {
  struct Request;
  struct Socket;

  net::io_context context{1};  // first: the handlers it still holds are destroyed before the rest
  tcp::acceptor acceptor{context};
  net::signal_set signals{context, SIGINT, SIGTERM};
  net::steady_timer sweep{context};
  net::steady_timer retry{context};
  LiveServer* server = nullptr;
  Shared* shared = nullptr;
  std::string page;
  std::list<std::weak_ptr<Request>> pending;  // connections still sending their request, oldest first
  std::map<int, std::shared_ptr<Socket>> sockets;
  int next_client = 1;
  Clock::time_point window = Clock::now();  // the second in which `opened` WebSockets were accepted
  int opened = 0;
  std::thread thread;

  void accept();
  void check_sockets();
  void pump(int client);
  void resume(int client);
};

// One HTTP connection until its request is answered or becomes a WebSocket.
struct LiveServer::Io::Request : std::enable_shared_from_this<Request> {
  Request(Io& owner, tcp::socket socket) : io(owner), stream(std::move(socket)) {}
  Io& io;
  beast::tcp_stream stream;
  std::string head;
  bool answered = false;
  http::response<http::string_body> answer;
  char drain[4096];

  void start() {
    stream.expires_after(millis(kRequestSeconds));
    net::async_read_until(stream, net::dynamic_buffer(head, kRequestCap), "\r\n\r\n",
                          [self = shared_from_this()](error_code error, std::size_t size) { self->on_head(error, size); });
  }
  void on_head(error_code error, std::size_t size);
  void refuse(http::status status, const std::string& body, const std::string& line = "");
  void respond(http::status status, const char* type, std::string body);
  void discard();
};

// One WebSocket: Beast's stream, what is being written to it, when it was last heard.
struct LiveServer::Io::Socket : std::enable_shared_from_this<Socket> {
  Socket(Io& owner, beast::tcp_stream&& stream, int client_id) : io(owner), ws(std::move(stream)), id(client_id) {}
  Io& io;
  websocket::stream<beast::tcp_stream> ws;
  int id;
  beast::flat_buffer in;
  Clock::time_point heard = Clock::now(), progress = Clock::now();
  bool spoke = false, writing = false, closed = false;
  std::deque<std::pair<std::string, bool>> batch;  // messages being written (binary: true)
  std::size_t batch_text_bytes = 0;                 // the batch's bytes but its frame's

  std::string name() const { return "page " + std::to_string(id); }
  void read();
  void on_read(error_code error);
  void write_next();
  void drop(const std::string& line);
  void gone();
};

void LiveServer::Io::Request::refuse(http::status status, const std::string& body, const std::string& line) {
  if (!line.empty()) live_log(line);
  respond(status, "text/plain; charset=utf-8", body + "\n");
}

void LiveServer::Io::Request::respond(http::status status, const char* type, std::string body) {
  answered = true;
  answer = http::response<http::string_body>(status, 11);
  answer.set(http::field::content_type, type);
  answer.set(http::field::cache_control, "no-store");
  if (status == http::status::service_unavailable) answer.set(http::field::retry_after, "1");
  answer.keep_alive(false);
  answer.body() = std::move(body);
  answer.prepare_payload();
  stream.expires_after(millis(kStalledSeconds));
  http::async_write(stream, answer, [self = shared_from_this()](error_code error, std::size_t) {
    if (error) return self->stream.close();
    self->stream.socket().shutdown(tcp::socket::shutdown_send, error);
    self->stream.expires_after(std::chrono::seconds(2));
    self->discard();  // what the client still sends is read and dropped: closing on it would reset the answer away
  });
}

void LiveServer::Io::Request::discard() {
  stream.async_read_some(net::buffer(drain), [self = shared_from_this()](error_code error, std::size_t) {
    if (error) return self->stream.close();
    self->discard();
  });
}

void LiveServer::Io::Request::on_head(error_code error, std::size_t size) {
  if (error == net::error::not_found) return refuse(http::status::request_header_fields_too_large, "live: a request head over 8 KiB");
  if (error) return;  // closed, reset, or silent for kRequestSeconds: its slot goes to the next one
  const std::string raw = head.substr(0, size);
  if (live_head_folded(raw)) return refuse(http::status::bad_request, "live: a folded header line (RFC 7230 §3.2.4)");
  http::request_parser<http::empty_body> parser;
  parser.header_limit(static_cast<std::uint32_t>(kRequestCap));
  parser.put(net::buffer(raw), error);
  if (error || !parser.is_header_done()) return refuse(http::status::bad_request, "live: a malformed request");
  const http::request<http::empty_body>& request = parser.get();
  std::string repeated;  // a header this server reads, given twice (which one counts is anybody's guess)
  std::set<std::string> seen;
  for (const auto& field : request) {
    const std::string name = lower(std::string(field.name_string()));
    const bool read = name == "host" || name == "origin" || name == "upgrade" || name.rfind("sec-websocket-", 0) == 0;
    if (read && !seen.insert(name).second) repeated = name;
  }
  const int port = io.server->port();
  if (request.method() != http::verb::get) return refuse(http::status::method_not_allowed, "live: only GET");
  if (!repeated.empty()) {
    return refuse(http::status::bad_request, "live: a header given twice (" + shown(repeated) + ")",
                  "live: a request with two " + shown(repeated) + " headers, refused (400)");
  }
  const auto host = request.find(http::field::host);
  if (host == request.end()) return refuse(http::status::bad_request, "live: a request without Host");
  if (!live_host_allowed(std::string(host->value()), port)) {
    return refuse(http::status::forbidden, "live: a request for another host",
                  "live: a request for the host '" + shown(host->value()) + "', refused (403)");
  }
  const std::string target(request.target());
  const std::size_t question = target.find('?');
  const std::string path = target.substr(0, question);
  if (path != "/" && path != "/ws") return refuse(http::status::not_found, "live: not found (the page is /?token=...)");
  const bool upgrade = websocket::is_upgrade(request);
  if (!live_token_matches(question == std::string::npos ? std::nullopt : std::optional<std::string>(target.substr(question + 1)),
                          io.server->token())) {
    return refuse(http::status::forbidden, "live: wrong or missing token (open the URL the program printed)",
                  path == "/" && !upgrade ? "live: a request for the page without the run's token, refused (403)"
                                          : "live: a WebSocket without the run's token, refused (403)");
  }
  if (path == "/") return respond(http::status::ok, "text/html; charset=utf-8", io.page);
  const auto origin = request.find(http::field::origin);
  if (!live_origin_allowed(origin == request.end() ? std::nullopt : std::optional<std::string>(std::string(origin->value())), port)) {
    return refuse(http::status::forbidden, "live: a WebSocket from a foreign Origin",
                  "live: a WebSocket from the foreign Origin '" + shown(origin->value()) + "', refused (403)");
  }
  if (!upgrade) return refuse(http::status::bad_request, "live: /ws is a WebSocket (version 13)");
  // A storm of reconnections costs the run a bounded amount a second, whatever its rate.
  const Clock::time_point now = Clock::now();
  if (since(io.window, now) >= 1.0) io.window = now, io.opened = 0;
  if (++io.opened > kNewSocketsPerSecond) {
    return refuse(http::status::service_unavailable, "live: too many new WebSockets this second; try again",
                  "live: over " + std::to_string(kNewSocketsPerSecond) + " new WebSockets in a second, refused (503)");
  }
  answered = true;
  stream.expires_never();  // the WebSocket's own timeouts take over (Beast's idle timeout and pings)
  beast::error_code ignored;
  stream.socket().set_option(net::socket_base::send_buffer_size(static_cast<int>(kSendBufferBytes)), ignored);
  auto socket = std::make_shared<Socket>(io, std::move(stream), 0);
  socket->ws.set_option(websocket::stream_base::timeout{millis(kRequestSeconds), millis(kSilentSeconds), true});
  socket->ws.read_message_max(kLiveMessageCap);
  socket->ws.auto_fragment(false);  // a message is one frame, as the page and the checks read it
  socket->ws.control_callback([raw = socket.get()](websocket::frame_type kind, beast::string_view) {
    raw->heard = Clock::now();
    // Beast takes a close code over 4999, which RFC 6455 §7.4.2 leaves undefined: answered as 999 is.
    if (kind == websocket::frame_type::close && raw->ws.reason().code > 4999) {
      raw->ws.async_close(websocket::close_code::protocol_error, [self = raw->shared_from_this()](error_code) {});
    }
  });
  socket->ws.async_accept(request, [socket](error_code accept_error) {
    if (accept_error) return;  // Beast answered a bad handshake itself (400, 426)
    Io& owner = socket->io;
    if (static_cast<int>(owner.sockets.size()) >= kMaxClients) {
      // A reload or a new tab always connects: the oldest of the clients that never said a word makes
      // room, else the one heard from least recently.
      auto rank = [](const std::shared_ptr<Socket>& other) { return std::make_pair(other->spoke, other->heard); };
      auto quietest = std::min_element(owner.sockets.begin(), owner.sockets.end(),
                                       [&rank](const auto& a, const auto& b) { return rank(a.second) < rank(b.second); });
      quietest->second->drop("live: " + quietest->second->name() + " closed: a new page came and it was heard from least recently");
    }
    socket->id = owner.next_client++;
    owner.sockets[socket->id] = socket;
    {
      const std::lock_guard<std::mutex> lock(owner.shared->mutex);
      owner.shared->clients[socket->id].inbound.push_back(LiveInbound{socket->id, {}, false, true});
    }
    owner.shared->inbound_ready.notify_one();
    socket->read();
  });
}

void LiveServer::Io::Socket::read() {
  ws.async_read(in, [self = shared_from_this()](error_code error, std::size_t) { self->on_read(error); });
}

void LiveServer::Io::Socket::on_read(error_code error) {
  if (error) {
    if (error == websocket::error::message_too_big) {
      live_log("live: " + name() + " closed: a message over " + std::to_string(kLiveMessageCap) + " bytes (close 1009)");
    } else if (error != websocket::error::closed && error != net::error::operation_aborted && error != net::error::eof &&
               error != net::error::connection_reset && !closed) {
      live_log("live: " + name() + " closed: " + error.message());
    }
    return gone();
  }
  heard = Clock::now();
  spoke = true;
  std::string text = beast::buffers_to_string(in.data());
  in.consume(in.size());
  bool full = false;
  {
    const std::lock_guard<std::mutex> lock(io.shared->mutex);
    Shared::Client& client = io.shared->clients[id];
    if (ws.got_binary()) {
      const std::string line = "live: a binary message, refused (a command is JSON text)";
      live_log(line);
      client.texts.push_back(error_message(line));
      client.text_bytes += client.texts.back().size();
    } else {
      client.inbound.push_back(LiveInbound{id, std::move(text), false, false});
    }
    full = client.inbound.size() >= kInboundPerClient;
    client.unread = full;  // read again once the loop has taken some (take_inbound, resume)
  }
  io.shared->inbound_ready.notify_one();
  io.pump(id);
  if (!full) read();
}

// The client's outbox into its socket, one message after another: texts first, then the newest frame.
void LiveServer::Io::pump(int client) {
  const auto found = sockets.find(client);
  if (found == sockets.end() || found->second->writing || found->second->closed) return;
  Socket& socket = *found->second;
  {
    const std::lock_guard<std::mutex> lock(shared->mutex);
    Shared::Client& outbox = shared->clients[client];
    for (std::string& text : outbox.texts) socket.batch.emplace_back(std::move(text), false);
    socket.batch_text_bytes = outbox.text_bytes;
    outbox.texts.clear();
    outbox.text_bytes = 0;
    if (outbox.frame) {
      socket.batch.emplace_back(std::move(outbox.status), false);
      socket.batch.emplace_back(std::move(outbox.data), true);
      outbox.frame = false;
    }
  }
  if (socket.batch.empty()) return;
  socket.writing = true;
  socket.progress = Clock::now();
  socket.write_next();
}

void LiveServer::Io::Socket::write_next() {
  if (batch.empty()) {
    writing = false;
    batch_text_bytes = 0;
    return io.pump(id);
  }
  ws.binary(batch.front().second);
  ws.async_write(net::buffer(batch.front().first), [self = shared_from_this()](error_code error, std::size_t) {
    if (error) return self->gone();
    self->progress = Clock::now();
    const std::size_t size = self->batch.front().first.size();
    self->batch_text_bytes -= std::min(self->batch_text_bytes, size);
    self->batch.pop_front();
    self->write_next();
  });
}

void LiveServer::Io::Socket::drop(const std::string& line) {
  if (closed) return;
  live_log(line);
  beast::get_lowest_layer(ws).close();  // its pending read and write end with an error: gone()
  gone();
}

void LiveServer::Io::Socket::gone() {
  if (closed) return;
  closed = true;
  io.sockets.erase(id);
  {
    const std::lock_guard<std::mutex> lock(io.shared->mutex);
    Shared::Client& client = io.shared->clients[id];
    client.gone = true;
    client.texts.clear();
    client.frame = false;
    client.inbound.push_back(LiveInbound{id, {}, true, false});
  }
  io.shared->inbound_ready.notify_one();
}

void LiveServer::Io::resume(int client) {
  const auto found = sockets.find(client);
  if (found != sockets.end() && !found->second->closed) found->second->read();
}

void LiveServer::Io::accept() {
  acceptor.async_accept(context, [this](error_code error, tcp::socket socket) {
    if (error == net::error::operation_aborted) return;
    if (error) {  // out of descriptors, say: try again shortly rather than spin
      retry.expires_after(std::chrono::milliseconds(50));
      return retry.async_wait([this](error_code) { accept(); });
    }
    beast::error_code ignored;
    // A frame is two writes (its status, then its data): with Nagle's algorithm the second waited for the page's delayed ACK.
    socket.set_option(tcp::no_delay(true), ignored);
    pending.remove_if([](const std::weak_ptr<Request>& request) {
      const auto held = request.lock();
      return !held || held->answered;
    });
    if (static_cast<int>(pending.size()) >= kMaxPending) {  // the newest comer gets the slot: a reload always can
      if (const auto oldest = pending.front().lock()) oldest->stream.close();
      pending.pop_front();
    }
    auto request = std::make_shared<Request>(*this, std::move(socket));
    pending.push_back(request);
    request->start();
    accept();
  });
}

// Every quarter second: a client whose writes made no progress for kStalledSeconds, or with over
// kOutboxBytes waiting for it (every byte but its frame, which the next replaces), is dropped.
void LiveServer::Io::check_sockets() {
  const Clock::time_point now = Clock::now();
  std::vector<std::pair<std::shared_ptr<Socket>, std::string>> drops;
  for (const auto& [id, socket] : sockets) {
    std::size_t queued = socket->batch_text_bytes;
    {
      const std::lock_guard<std::mutex> lock(shared->mutex);
      queued += shared->clients[id].text_bytes;
    }
    if (queued > kOutboxBytes) {
      drops.emplace_back(socket, "live: " + socket->name() + " dropped: over " + std::to_string(kOutboxBytes >> 20) +
                                     " MB waiting for it (it reads too little of what it asks for)");
    } else if (socket->writing && since(socket->progress, now) > kStalledSeconds) {
      drops.emplace_back(socket, "live: " + socket->name() + " dropped: it took nothing off its socket for " +
                                     std::to_string(int(kStalledSeconds)) + " s");
    }
  }
  for (auto& [socket, line] : drops) socket->drop(line);
  sweep.expires_after(std::chrono::milliseconds(250));
  sweep.async_wait([this](error_code error) {
    if (!error) check_sockets();
  });
}

LiveServer::LiveServer(int port, std::string page)
    : token_(live_token()), shared_(std::make_unique<Shared>()), io_(std::make_unique<Io>()) {
  const tcp::endpoint endpoint(net::ip::address_v4::loopback(), static_cast<unsigned short>(port));
  error_code error;
  io_->acceptor.open(endpoint.protocol(), error);
  if (!error) io_->acceptor.set_option(net::socket_base::reuse_address(true), error);
  if (!error) io_->acceptor.bind(endpoint, error);
  if (!error) io_->acceptor.listen(128, error);
  if (error) throw InputError("--live: cannot listen on 127.0.0.1:" + std::to_string(port) + " (" + error.message() + ")");
  port_ = io_->acceptor.local_endpoint().port();
  io_->server = this;
  io_->shared = shared_.get();
  io_->page = std::move(page);
  io_->signals.async_wait([shared = shared_.get()](error_code signal_error, int) {
    if (signal_error) return;
    shared->stop = true;
    shared->inbound_ready.notify_all();
  });
  io_->accept();
  io_->check_sockets();
  io_->thread = std::thread([io = io_.get()] { io->context.run(); });
}

LiveServer::~LiveServer() {
  io_->context.stop();
  io_->thread.join();
  io_->sockets.clear();
  io_->pending.clear();
}

std::string LiveServer::url() const { return "http://127.0.0.1:" + std::to_string(port_) + "/?token=" + token_; }

bool LiveServer::stop_requested() const { return shared_->stop; }

std::vector<LiveInbound> LiveServer::take_inbound() {
  std::vector<LiveInbound> taken;
  std::vector<int> unread;
  {
    const std::lock_guard<std::mutex> lock(shared_->mutex);
    auto& clients = shared_->clients;
    std::size_t turns = clients.size();
    auto client = clients.upper_bound(shared_->last_taken);
    for (; turns > 0 && taken.size() < kTakePerTurn; --turns) {
      if (client == clients.end()) client = clients.begin();
      std::deque<LiveInbound>& queue = client->second.inbound;
      bool closed = false;
      for (std::size_t k = 0; k < kTakePerClient && !queue.empty() && taken.size() < kTakePerTurn; ++k) {
        closed = queue.front().closed;
        // A page that came and has gone already costs the loop nothing: no hello is built for it.
        if (!(queue.front().opened && client->second.gone)) taken.push_back(std::move(queue.front()));
        queue.pop_front();
      }
      if (client->second.unread && queue.size() < kInboundPerClient) {
        client->second.unread = false;
        unread.push_back(client->first);
      }
      shared_->last_taken = client->first;
      client = closed ? clients.erase(client) : std::next(client);
    }
  }
  if (!unread.empty()) {  // the server reads again from a client it had stopped reading
    net::post(io_->context, [io = io_.get(), unread] {
      for (const int client : unread) io->resume(client);
    });
  }
  return taken;
}

void LiveServer::wait_inbound(double seconds) {
  std::unique_lock<std::mutex> lock(shared_->mutex);
  if (seconds <= 0.0 || shared_->stop) return;
  for (const auto& [id, client] : shared_->clients) {
    if (!client.inbound.empty()) return;
  }
  shared_->inbound_ready.wait_for(lock, std::chrono::duration<double>(seconds));
}

void LiveServer::send_text(int client, const std::string& text) {
  {
    const std::lock_guard<std::mutex> lock(shared_->mutex);
    for (auto& [id, entry] : shared_->clients) {
      if ((client >= 0 && id != client) || entry.gone) continue;
      entry.texts.push_back(text);
      entry.text_bytes += text.size();
    }
  }
  net::post(io_->context, [io = io_.get(), client] {
    if (client >= 0) return io->pump(client);
    std::vector<int> all;
    for (const auto& [id, socket] : io->sockets) all.push_back(id);
    for (const int id : all) io->pump(id);
  });
}

std::vector<int> LiveServer::ready_clients() {
  const std::lock_guard<std::mutex> lock(shared_->mutex);
  std::vector<int> ready;
  for (const auto& [id, entry] : shared_->clients) {
    if (!entry.gone && entry.in_flight < kFramesInFlight) ready.push_back(id);
  }
  return ready;
}

void LiveServer::send_frame(int client, const std::string& text, const std::vector<float>& frame) {
  {
    const std::lock_guard<std::mutex> lock(shared_->mutex);
    const auto found = shared_->clients.find(client);
    if (found == shared_->clients.end() || found->second.gone) return;
    found->second.status = text;
    found->second.data.assign(reinterpret_cast<const char*>(frame.data()), frame.size() * sizeof(float));
    found->second.frame = true;
    ++found->second.in_flight;
  }
  net::post(io_->context, [io = io_.get(), client] { io->pump(client); });
}

void LiveServer::acknowledge(int client) {
  const std::lock_guard<std::mutex> lock(shared_->mutex);
  const auto found = shared_->clients.find(client);
  if (found != shared_->clients.end() && found->second.in_flight > 0) --found->second.in_flight;
}

int LiveServer::clients() {
  const std::lock_guard<std::mutex> lock(shared_->mutex);
  int count = 0;
  for (const auto& [id, entry] : shared_->clients) count += entry.gone ? 0 : 1;
  return count;
}

}  // namespace cl
