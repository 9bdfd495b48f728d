#include "common/live_server.h"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <condition_variable>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <list>
#include <map>
#include <mutex>
#include <random>
#include <set>
#include <thread>
#include <utility>

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
double since(Clock::time_point then) { return std::chrono::duration<double>(Clock::now() - then).count(); }
std::chrono::milliseconds millis(double seconds) { return std::chrono::milliseconds(static_cast<long>(seconds * 1000.0)); }

// A header's value as a stderr line may show it: at most 80 bytes, printable ASCII ('?' for the rest).
std::string shown(beast::string_view text) {
  std::string out(text.data(), std::min<std::size_t>(text.size(), 80));
  for (char& c : out) c = static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f ? '?' : c;
  return out;
}

struct LogState {
  std::mutex mutex;
  Clock::time_point window = Clock::now();
  int printed = 0;
  long hidden = 0;
} log_state;

void log_roll(bool final) {  // with log_state.mutex held
  if (since(log_state.window) < 1.0 && !final) return;
  if (log_state.hidden > 0) {
    std::fprintf(stderr, "live: %ld more lines like these in the last %.0f s, not shown\n", log_state.hidden,
                 std::max(1.0, since(log_state.window)));
  }
  log_state.window = Clock::now();
  log_state.printed = 0;
  log_state.hidden = 0;
}

}  // namespace

void live_log(const std::string& line) {
  const std::lock_guard<std::mutex> lock(log_state.mutex);
  log_roll(false);
  if (log_state.printed++ < kLiveLogPerSecond) std::fprintf(stderr, "%s\n", line.c_str());
  else ++log_state.hidden;
}

void live_log_flush(bool final) {
  const std::lock_guard<std::mutex> lock(log_state.mutex);
  log_roll(final);
}

std::string live_token() {
  std::random_device device;
  std::string token;
  for (int word = 0; word < 4; ++word) {
    std::uint32_t bits = device();
    for (int d = 0; d < 8; ++d, bits >>= 4) token += "0123456789abcdef"[bits & 15u];
  }
  return token;
}

std::string live_forwarded_host(int port, const char* codespace, const char* domain) {
  if (codespace == nullptr || domain == nullptr || *codespace == '\0' || *domain == '\0') return "";
  return std::string(codespace) + "-" + std::to_string(port) + "." + domain;
}

namespace {
// The name a GitHub Codespace forwards this port under, from its environment ("" elsewhere).
std::string codespace_host(int port) {
  return live_forwarded_host(port, std::getenv("CODESPACE_NAME"), std::getenv("GITHUB_CODESPACES_PORT_FORWARDING_DOMAIN"));
}
}  // namespace

bool live_origin_allowed(const std::optional<std::string>& origin, int port) {
  const std::string tail = ":" + std::to_string(port);
  const std::string forwarded = codespace_host(port);
  return !origin || *origin == "http://127.0.0.1" + tail || *origin == "http://localhost" + tail ||
         (!forwarded.empty() && *origin == "https://" + forwarded);
}

bool live_host_allowed(const std::string& host, int port) {
  const std::string tail = ":" + std::to_string(port);
  const std::string forwarded = codespace_host(port);
  return host == "127.0.0.1" + tail || host == "localhost" + tail || (port == 80 && (host == "127.0.0.1" || host == "localhost")) ||
         (!forwarded.empty() && host == forwarded);
}

bool live_token_matches(const std::optional<std::string>& query, const std::string& token) {
  if (!query || token.empty()) return false;
  for (std::size_t start = 0; start <= query->size();) {
    const std::size_t end = std::min(query->find('&', start), query->size());
    if (query->compare(start, end - start, "token=" + token) == 0 && end - start == token.size() + 6) return true;
    start = end + 1;
  }
  return false;
}

bool live_head_folded(const std::string& head) {
  return head.find("\r\n ") != std::string::npos || head.find("\r\n\t") != std::string::npos;
}

struct LiveServer::State {
  struct Request;
  struct Socket;
  // What the live loop and the server's thread share, under `mutex`: each client's messages, and its
  // frames in flight. Everything else is the server thread's alone; the loop posts to it.
  struct Inbox {
    std::deque<LiveInbound> inbound;    // ends with the closing once the client has gone
    bool gone = false, unread = false;  // unread: its queue was full, the server stopped reading it
    int in_flight = 0;
  };
  std::mutex mutex;
  std::condition_variable inbound_ready;
  std::map<int, Inbox> inboxes;
  int last_taken = 0;  // take_inbound starts after this client: every client gets its turn
  std::atomic<bool> stop{false};

  net::io_context context{1};  // before what its handlers hold: destroyed after them
  tcp::acceptor acceptor{context};
  net::signal_set signals{context, SIGINT, SIGTERM};
  net::steady_timer sweep{context}, retry{context};
  LiveServer* server = nullptr;
  std::string page;
  std::list<std::weak_ptr<Request>> pending;  // connections still sending their request, oldest first
  std::map<int, std::shared_ptr<Socket>> sockets;
  int next_client = 1, opened = 0;  // opened: the WebSockets accepted in the second since `window`
  Clock::time_point window = Clock::now();
  std::thread thread;

  void accept();
  void check_stalls();
  void inbound(const LiveInbound& event, bool* full = nullptr) {
    {
      const std::lock_guard<std::mutex> lock(mutex);
      Inbox& inbox = inboxes[event.client];
      inbox.gone = inbox.gone || event.closed;
      inbox.inbound.push_back(event);
      if (full) *full = inbox.unread = inbox.inbound.size() >= kInboundPerClient;  // read again once the loop took some
    }
    inbound_ready.notify_one();
  }
  template <class Action> void post(Action action) { net::post(context, std::move(action)); }
};

// One HTTP connection until its request is answered or becomes a WebSocket.
struct LiveServer::State::Request : std::enable_shared_from_this<Request> {
  Request(State& owner, tcp::socket socket) : state(owner), stream(std::move(socket)) {}
  State& state;
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
  void respond(http::status status, std::string body, const std::string& line = "", const char* type = "text/plain; charset=utf-8") {
    if (!line.empty()) live_log(line);
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
  void discard() {
    stream.async_read_some(net::buffer(drain), [self = shared_from_this()](error_code error, std::size_t) {
      if (error) return self->stream.close();
      self->discard();
    });
  }
  void on_head(error_code error, std::size_t size);
};

// One WebSocket: Beast's stream, its outbox (texts in order, then the newest frame), when it was last heard.
struct LiveServer::State::Socket : std::enable_shared_from_this<Socket> {
  struct Message {
    std::string bytes;
    bool binary = false, counted = true;  // counted: a text, not a frame's part (which the next replaces)
  };
  Socket(State& owner, beast::tcp_stream&& stream) : state(owner), ws(std::move(stream)) {}
  State& state;
  websocket::stream<beast::tcp_stream> ws;
  int id = 0;
  beast::flat_buffer in;
  Clock::time_point heard = Clock::now(), progress = Clock::now();
  bool spoke = false, writing = false, closed = false;
  std::deque<Message> out;
  std::size_t out_bytes = 0;
  std::string status, data;  // the newest frame, when `frame`
  bool frame = false;

  std::string name() const { return "page " + std::to_string(id); }
  void read() {
    ws.async_read(in, [self = shared_from_this()](error_code error, std::size_t) { self->on_read(error); });
  }
  void on_read(error_code error);
  void send(const std::string& text) {
    out.push_back({text});
    out_bytes += text.size();
    if (out_bytes > kOutboxBytes) {
      return drop("live: " + name() + " dropped: over " + std::to_string(kOutboxBytes >> 20) +
                  " MB waiting for it (it reads too little of what it asks for)");
    }
    write_next();
  }
  void write_next() {
    if (writing || closed) return;
    if (out.empty() && std::exchange(frame, false)) {
      out.push_back({std::move(status), false, false});
      out.push_back({std::move(data), true, false});
    }
    if (out.empty()) return;
    writing = true;
    progress = Clock::now();
    ws.binary(out.front().binary);
    ws.async_write(net::buffer(out.front().bytes), [self = shared_from_this()](error_code error, std::size_t) {
      if (error) return self->gone();
      if (self->out.front().counted) self->out_bytes -= self->out.front().bytes.size();
      self->out.pop_front();
      self->writing = false;
      self->write_next();
    });
  }
  void drop(const std::string& line) {
    if (closed) return;
    live_log(line);
    beast::get_lowest_layer(ws).close();  // its pending read and write end with an error
    gone();
  }
  void gone() {
    if (closed) return;
    closed = true;
    const auto self = shared_from_this();
    state.sockets.erase(id);
    state.inbound(LiveInbound{id, {}, true, false});
  }
};

void LiveServer::State::Request::on_head(error_code error, std::size_t size) {
  using status = http::status;
  if (error == net::error::not_found) return respond(status::request_header_fields_too_large, "live: a request head over 8 KiB\n");
  if (error) return;  // closed, reset, or silent for kRequestSeconds: its slot goes to the next one
  const std::string raw = head.substr(0, size);
  if (live_head_folded(raw)) return respond(status::bad_request, "live: a folded header line (RFC 7230 §3.2.4)\n");
  http::request_parser<http::empty_body> parser;
  parser.header_limit(static_cast<std::uint32_t>(kRequestCap));
  parser.put(net::buffer(raw), error);
  if (error || !parser.is_header_done()) return respond(status::bad_request, "live: a malformed request\n");
  const http::request<http::empty_body>& request = parser.get();
  std::string repeated;  // a header this server reads, given twice (which one counts is anybody's guess)
  std::set<std::string> seen;
  for (const auto& field : request) {
    std::string name(field.name_string());
    std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    const bool read = name == "host" || name == "origin" || name == "upgrade" || name.rfind("sec-websocket-", 0) == 0;
    if (read && !seen.insert(name).second) repeated = name;
  }
  const int port = state.server->port();
  if (request.method() != http::verb::get) return respond(status::method_not_allowed, "live: only GET\n");
  if (!repeated.empty()) {
    return respond(status::bad_request, "live: a header given twice (" + repeated + ")\n",
                   "live: a request with two " + shown(repeated) + " headers, refused (400)");
  }
  const auto host = request.find(http::field::host);
  if (host == request.end()) return respond(status::bad_request, "live: a request without Host\n");
  if (!live_host_allowed(std::string(host->value()), port)) {
    return respond(status::forbidden, "live: a request for another host\n",
                   "live: a request for the host '" + shown(host->value()) + "', refused (403)");
  }
  const std::string target(request.target());
  const std::size_t question = target.find('?');
  const std::string path = target.substr(0, question);
  if (path != "/" && path != "/ws") return respond(status::not_found, "live: not found (the page is /?token=...)\n");
  const bool upgrade = websocket::is_upgrade(request);
  const auto query = question == std::string::npos ? std::nullopt : std::optional<std::string>(target.substr(question + 1));
  if (!live_token_matches(query, state.server->token())) {
    return respond(status::forbidden, "live: wrong or missing token (open the URL the program printed)\n",
                   path == "/" && !upgrade ? "live: a request for the page without the run's token, refused (403)"
                                           : "live: a WebSocket without the run's token, refused (403)");
  }
  if (path == "/") return respond(status::ok, state.page, "", "text/html; charset=utf-8");
  const auto origin = request.find(http::field::origin);
  if (!live_origin_allowed(origin == request.end() ? std::nullopt : std::optional<std::string>(origin->value()), port)) {
    return respond(status::forbidden, "live: a WebSocket from a foreign Origin\n",
                   "live: a WebSocket from the foreign Origin '" + shown(origin->value()) + "', refused (403)");
  }
  if (!upgrade) return respond(status::bad_request, "live: /ws is a WebSocket (version 13)\n");
  // A storm of reconnections costs the run a bounded amount a second, whatever its rate.
  if (since(state.window) >= 1.0) state.window = Clock::now(), state.opened = 0;
  if (++state.opened > kNewSocketsPerSecond) {
    return respond(status::service_unavailable, "live: too many new WebSockets this second; try again\n",
                   "live: over " + std::to_string(kNewSocketsPerSecond) + " new WebSockets in a second, refused (503)");
  }
  answered = true;
  stream.expires_never();  // the WebSocket's own timeouts take over (Beast's idle timeout and pings)
  stream.socket().set_option(net::socket_base::send_buffer_size(static_cast<int>(kSendBufferBytes)), error);
  auto socket = std::make_shared<Socket>(state, std::move(stream));
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
    State& owner = socket->state;
    if (static_cast<int>(owner.sockets.size()) >= kMaxClients) {
      // A reload or a new tab always connects: the oldest of the clients that never said a word makes
      // room, else the one heard from least recently.
      auto rank = [](const auto& entry) { return std::make_pair(entry.second->spoke, entry.second->heard); };
      const auto quietest = std::min_element(owner.sockets.begin(), owner.sockets.end(),
                                             [&rank](const auto& a, const auto& b) { return rank(a) < rank(b); })->second;
      quietest->drop("live: " + quietest->name() + " closed: a new page came and it was heard from least recently");
    }
    socket->id = owner.next_client++;
    owner.sockets[socket->id] = socket;
    owner.inbound(LiveInbound{socket->id, {}, false, true});
    socket->read();
  });
}

void LiveServer::State::Socket::on_read(error_code error) {
  if (error == websocket::error::message_too_big) {
    live_log("live: " + name() + " closed: a message over " + std::to_string(kLiveMessageCap) + " bytes (close 1009)");
  } else if (error && error != websocket::error::closed && error != net::error::operation_aborted &&
             error != net::error::eof && error != net::error::connection_reset && !closed) {
    live_log("live: " + name() + " closed: " + error.message());
  }
  if (error) return gone();
  heard = Clock::now();
  spoke = true;
  bool full = false;
  if (ws.got_binary()) {
    const std::string line = "live: a binary message, refused (a command is JSON text)";
    live_log(line);
    send(live_json_text(nlohmann::json{{"type", "error"}, {"text", line}}));
  } else {
    state.inbound(LiveInbound{id, beast::buffers_to_string(in.data()), false, false}, &full);
  }
  in.consume(in.size());
  if (!full && !closed) read();
}

void LiveServer::State::accept() {
  acceptor.async_accept(context, [this](error_code error, tcp::socket socket) {
    if (error == net::error::operation_aborted) return;
    if (error) {  // out of descriptors, say: try again shortly rather than spin
      retry.expires_after(std::chrono::milliseconds(50));
      return retry.async_wait([this](error_code) { accept(); });
    }
    // A frame is two writes (its status, then its data): with Nagle's algorithm the second waited for the page's delayed ACK.
    socket.set_option(tcp::no_delay(true), error);
    pending.remove_if([](const std::weak_ptr<Request>& request) { return request.expired() || request.lock()->answered; });
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

// Every quarter second: a client whose writes made no progress for kStalledSeconds is dropped.
void LiveServer::State::check_stalls() {
  std::vector<std::shared_ptr<Socket>> stalled;
  for (const auto& [id, socket] : sockets) {
    if (socket->writing && since(socket->progress) > kStalledSeconds) stalled.push_back(socket);
  }
  for (const auto& socket : stalled) {
    socket->drop("live: " + socket->name() + " dropped: it took nothing off its socket for " +
                 std::to_string(int(kStalledSeconds)) + " s");
  }
  sweep.expires_after(std::chrono::milliseconds(250));
  sweep.async_wait([this](error_code error) {
    if (!error) check_stalls();
  });
}

LiveServer::LiveServer(int port, std::string page) : token_(live_token()), state_(std::make_unique<State>()) {
  State& state = *state_;
  const tcp::endpoint endpoint(net::ip::address_v4::loopback(), static_cast<unsigned short>(port));
  error_code error;
  state.acceptor.open(endpoint.protocol(), error);
  if (!error) state.acceptor.set_option(net::socket_base::reuse_address(true), error);
  if (!error) state.acceptor.bind(endpoint, error);
  if (!error) state.acceptor.listen(128, error);
  if (error) throw InputError("--live: cannot listen on 127.0.0.1:" + std::to_string(port) + " (" + error.message() + ")");
  port_ = state.acceptor.local_endpoint().port();
  state.server = this;
  state.page = std::move(page);
  state.signals.async_wait([&state](error_code signal_error, int) {
    if (signal_error) return;
    state.stop = true;
    state.inbound_ready.notify_all();
  });
  state.accept();
  state.check_stalls();
  state.thread = std::thread([&state] { state.context.run(); });
}

LiveServer::~LiveServer() {
  state_->context.stop();
  state_->thread.join();
  state_->sockets.clear();
  state_->pending.clear();
}

std::string LiveServer::url() const { return "http://127.0.0.1:" + std::to_string(port_) + "/?token=" + token_; }

bool LiveServer::stop_requested() const { return state_->stop; }

std::vector<LiveInbound> LiveServer::take_inbound() {
  std::vector<LiveInbound> taken;
  std::vector<int> unread;
  {
    const std::lock_guard<std::mutex> lock(state_->mutex);
    auto& inboxes = state_->inboxes;
    auto inbox = inboxes.upper_bound(state_->last_taken);
    for (std::size_t turns = inboxes.size(); turns > 0 && taken.size() < kTakePerTurn; --turns) {
      if (inbox == inboxes.end()) inbox = inboxes.begin();
      std::deque<LiveInbound>& queue = inbox->second.inbound;
      bool closed = false;
      for (std::size_t k = 0; k < kTakePerClient && !queue.empty() && taken.size() < kTakePerTurn; ++k) {
        closed = queue.front().closed;
        // A page that came and has gone already costs the loop nothing: no hello is built for it.
        if (!(queue.front().opened && inbox->second.gone)) taken.push_back(std::move(queue.front()));
        queue.pop_front();
      }
      if (inbox->second.unread && queue.size() < kInboundPerClient) inbox->second.unread = false, unread.push_back(inbox->first);
      state_->last_taken = inbox->first;
      inbox = closed ? inboxes.erase(inbox) : std::next(inbox);
    }
  }
  if (!unread.empty()) {  // the server reads again from a client it had stopped reading
    state_->post([state = state_.get(), unread] {
      for (const int id : unread) {
        if (state->sockets.count(id)) state->sockets[id]->read();
      }
    });
  }
  return taken;
}

void LiveServer::wait_inbound(double seconds) {
  std::unique_lock<std::mutex> lock(state_->mutex);
  if (seconds <= 0.0 || state_->stop) return;
  for (const auto& [id, inbox] : state_->inboxes) {
    if (!inbox.inbound.empty()) return;
  }
  state_->inbound_ready.wait_for(lock, std::chrono::duration<double>(seconds));
}

void LiveServer::send_text(int client, const std::string& text) {
  state_->post([state = state_.get(), client, text] {
    std::vector<std::shared_ptr<State::Socket>> to;
    for (const auto& [id, socket] : state->sockets) {
      if (client < 0 || id == client) to.push_back(socket);
    }
    for (const auto& socket : to) socket->send(text);
  });
}

std::vector<int> LiveServer::ready_clients() {
  const std::lock_guard<std::mutex> lock(state_->mutex);
  std::vector<int> ready;
  for (const auto& [id, inbox] : state_->inboxes) {
    if (!inbox.gone && inbox.in_flight < kFramesInFlight) ready.push_back(id);
  }
  return ready;
}

void LiveServer::send_frame(int client, const std::string& text, const std::vector<float>& frame) {
  {
    const std::lock_guard<std::mutex> lock(state_->mutex);
    const auto found = state_->inboxes.find(client);
    if (found == state_->inboxes.end() || found->second.gone) return;
    ++found->second.in_flight;
  }
  std::string data(reinterpret_cast<const char*>(frame.data()), frame.size() * sizeof(float));
  state_->post([state = state_.get(), client, text, data = std::move(data)]() mutable {
    const auto found = state->sockets.find(client);
    if (found == state->sockets.end()) return;
    State::Socket& socket = *found->second;
    socket.status = text;
    socket.data = std::move(data);
    socket.frame = true;  // a frame still waiting is replaced: the newest wins
    socket.write_next();
  });
}

void LiveServer::acknowledge(int client) {
  const std::lock_guard<std::mutex> lock(state_->mutex);
  const auto found = state_->inboxes.find(client);
  if (found != state_->inboxes.end() && found->second.in_flight > 0) --found->second.in_flight;
}

int LiveServer::clients() {
  const std::lock_guard<std::mutex> lock(state_->mutex);
  return static_cast<int>(std::count_if(state_->inboxes.begin(), state_->inboxes.end(),
                                        [](const auto& entry) { return !entry.second.gone; }));
}

}  // namespace cl
