#include "common/live_server.h"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <deque>
#include <list>
#include <map>
#include <mutex>
#include <random>
#include <thread>

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/socket.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "common/scene.h"

namespace cl {

namespace {

using Clock = std::chrono::steady_clock;

double since(Clock::time_point then, Clock::time_point now) { return std::chrono::duration<double>(now - then).count(); }

constexpr int kOpContinuation = 0x0, kOpText = 0x1, kOpBinary = 0x2, kOpClose = 0x8, kOpPing = 0x9, kOpPong = 0xa;

// SHA-1 (FIPS 180-4) of `text`, for the handshake's accept key only.
std::array<unsigned char, 20> sha1(const std::string& text) {
  std::uint32_t h[5] = {0x67452301u, 0xEFCDAB89u, 0x98BADCFEu, 0x10325476u, 0xC3D2E1F0u};
  std::string padded = text;
  padded += static_cast<char>(0x80);
  while (padded.size() % 64 != 56) padded += '\0';
  const std::uint64_t bits = static_cast<std::uint64_t>(text.size()) * 8u;
  for (int shift = 56; shift >= 0; shift -= 8) padded += static_cast<char>((bits >> shift) & 0xffu);
  auto rotate = [](std::uint32_t x, int by) { return (x << by) | (x >> (32 - by)); };
  for (std::size_t block = 0; block < padded.size(); block += 64) {
    std::uint32_t w[80];
    for (int t = 0; t < 16; ++t) {
      w[t] = 0;
      for (int b = 0; b < 4; ++b) w[t] = (w[t] << 8) | static_cast<unsigned char>(padded[block + std::size_t(4 * t + b)]);
    }
    for (int t = 16; t < 80; ++t) w[t] = rotate(w[t - 3] ^ w[t - 8] ^ w[t - 14] ^ w[t - 16], 1);
    std::uint32_t a = h[0], b = h[1], c = h[2], d = h[3], e = h[4];
    for (int t = 0; t < 80; ++t) {
      const std::uint32_t f = t < 20 ? (b & c) | (~b & d) : t < 40 ? b ^ c ^ d : t < 60 ? (b & c) | (b & d) | (c & d) : b ^ c ^ d;
      const std::uint32_t k = t < 20 ? 0x5A827999u : t < 40 ? 0x6ED9EBA1u : t < 60 ? 0x8F1BBCDCu : 0xCA62C1D6u;
      const std::uint32_t next = rotate(a, 5) + f + e + k + w[t];
      e = d, d = c, c = rotate(b, 30), b = a, a = next;
    }
    h[0] += a, h[1] += b, h[2] += c, h[3] += d, h[4] += e;
  }
  std::array<unsigned char, 20> digest{};
  for (int i = 0; i < 20; ++i) digest[std::size_t(i)] = static_cast<unsigned char>(h[i / 4] >> (24 - 8 * (i % 4)));
  return digest;
}

std::string base64(const unsigned char* data, std::size_t size) {
  static const char* digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < size; i += 3) {
    const std::uint32_t word = (std::uint32_t(data[i]) << 16) | (i + 1 < size ? std::uint32_t(data[i + 1]) << 8 : 0u) |
                               (i + 2 < size ? std::uint32_t(data[i + 2]) : 0u);
    out += digits[(word >> 18) & 63u];
    out += digits[(word >> 12) & 63u];
    out += i + 1 < size ? digits[(word >> 6) & 63u] : '=';
    out += i + 2 < size ? digits[word & 63u] : '=';
  }
  return out;
}

std::string lower(std::string text) {
  for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

// A header's value as a stderr line may show it: at most 80 bytes, printable ASCII ('?' for the rest).
std::string shown(const std::string& text) {
  std::string out = text.substr(0, 80);
  for (char& c : out) c = static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f ? '?' : c;
  return out;
}

std::string http_answer(int code, const char* reason, const std::string& body) {
  return "HTTP/1.1 " + std::to_string(code) + " " + reason + "\r\nContent-Type: text/plain; charset=utf-8\r\n" +
         "Content-Length: " + std::to_string(body.size()) + "\r\nConnection: close\r\nCache-Control: no-store\r\n\r\n" + body;
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

WebSocketHeader parse_websocket_header(const char* data, std::size_t size) {
  WebSocketHeader header;
  if (size < 2) return header;
  const auto byte = [data](std::size_t i) { return static_cast<unsigned char>(data[i]); };
  header.fin = (byte(0) & 0x80u) != 0;
  header.opcode = byte(0) & 0x0f;
  header.masked = (byte(1) & 0x80u) != 0;
  std::size_t at = 2;
  header.length = byte(1) & 0x7fu;
  if (header.length == 126) {
    if (size < 4) return header;
    header.length = (std::uint64_t(byte(2)) << 8) | byte(3);
    at = 4;
  } else if (header.length == 127) {
    if (size < 10) return header;
    header.length = 0;
    for (std::size_t i = 2; i < 10; ++i) header.length = (header.length << 8) | byte(i);
    at = 10;
  }
  if (header.masked) {
    if (size < at + 4) return header;
    for (std::size_t i = 0; i < 4; ++i) header.mask[i] = byte(at + i);
    at += 4;
  }
  header.size = at;
  header.complete = true;
  const bool control = (header.opcode & 0x8) != 0;
  header.bad = (byte(0) & 0x70u) != 0 || (header.length >> 63) != 0 || (control && (!header.fin || header.length > 125)) ||
               (header.opcode > kOpBinary && !control) || header.opcode > kOpPong;
  return header;
}

std::string websocket_frame(int opcode, const char* payload, std::size_t size) {
  std::string frame;
  frame += static_cast<char>(0x80 | (opcode & 0x0f));
  if (size < 126) {
    frame += static_cast<char>(size);
  } else if (size < 65536) {
    frame += static_cast<char>(126);
    frame += static_cast<char>((size >> 8) & 0xffu);
    frame += static_cast<char>(size & 0xffu);
  } else {
    frame += static_cast<char>(127);
    for (int shift = 56; shift >= 0; shift -= 8) frame += static_cast<char>((std::uint64_t(size) >> shift) & 0xffu);
  }
  frame.append(payload, size);
  return frame;
}

std::string websocket_accept(const std::string& key) {
  const std::array<unsigned char, 20> digest = sha1(key + "258EAFA5-E914-47DA-95CA-C5AB0DC85B11");
  return base64(digest.data(), digest.size());
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

// What the live loop and the server thread share, under `mutex`.
struct LiveServer::Shared {
  struct Client {
    std::deque<LiveInbound> inbound;  // ends with the closing once the client has gone
    bool gone = false;                // the server thread has closed it
    bool evict = false;               // the loop's side asks nothing of it; the server closes it
    std::deque<std::string> texts;    // framed, waiting for the socket
    std::size_t text_bytes = 0;
    std::string frame;                // framed status + data, the newest wins
    int in_flight = 0;
  };
  std::mutex mutex;
  std::condition_variable inbound_ready;
  std::map<int, Client> clients;
  int next_client = 1;
  int wake_fd = -1;

  void wake() const {
    const std::uint64_t one = 1;
    if (write(wake_fd, &one, sizeof one) < 0) { /* the counter is full: the server is awake anyway */ }
  }
};

// The server thread: its sockets and their buffers, touched by it alone.
struct LiveServer::Loop {
  enum class State { kRequest, kSocket, kClosing };
  struct Connection {
    int fd = -1;
    State state = State::kRequest;
    int client = 0;  // kSocket: its id in Shared::clients
    Clock::time_point opened, heard, progress, pinged;
    std::string in, out;
    std::size_t out_at = 0;
    std::string message;          // a fragmented text message so far
    bool in_message = false;      // continuation frames expected
    bool refusing = false;        // the message in progress is refused: its frames are discarded
    std::uint64_t skip = 0;       // payload bytes of a refused frame still to discard
    bool spoke = false;           // kSocket: it has sent something since its handshake
    std::string pong;             // the payload of the newest ping not answered yet (one pong answers them all)
    bool pong_due = false;
    std::size_t out_frame = 0;    // the bytes of `out` that are a frame (bounded: the newest wins), not counted
    Clock::time_point controls_since;  // the second in which `controls` control frames were read
    int controls = 0;
  };

  LiveServer* server = nullptr;
  Shared* shared = nullptr;
  std::string page;
  int listen_fd = -1;
  std::atomic<bool> stopping{false};
  std::list<Connection> connections;
  std::thread thread;

  void run();
  void accept_new(Clock::time_point now);
  bool read_some(Connection& connection, Clock::time_point now);
  void handle_request(Connection& connection, Clock::time_point now);
  void handle_frames(Connection& connection, Clock::time_point now);
  void fill(Connection& connection);
  bool write_some(Connection& connection, Clock::time_point now);
  void close_connection(std::list<Connection>::iterator connection, const std::string& why);
  void refuse(Connection& connection, int code, const char* reason, const std::string& body, const std::string& line);
  void to_client(Connection& connection, const std::string& line);
};

LiveServer::LiveServer(int port, std::string page)
    : token_(live_token()), shared_(std::make_unique<Shared>()), loop_(std::make_unique<Loop>()) {
  const int fd = socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<std::uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  const int yes = 1;
  if (fd >= 0) setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
  if (fd < 0 || bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0 || listen(fd, 128) != 0) {
    const std::string why = std::strerror(errno);
    if (fd >= 0) close(fd);
    throw InputError("--live: cannot listen on 127.0.0.1:" + std::to_string(port) + " (" + why + ")");
  }
  socklen_t length = sizeof address;
  getsockname(fd, reinterpret_cast<sockaddr*>(&address), &length);
  port_ = ntohs(address.sin_port);
  shared_->wake_fd = eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  if (shared_->wake_fd < 0) {
    close(fd);
    throw InputError(std::string("--live: eventfd: ") + std::strerror(errno));
  }
  loop_->server = this;
  loop_->shared = shared_.get();
  loop_->page = std::move(page);
  loop_->listen_fd = fd;
  loop_->thread = std::thread([loop = loop_.get()] { loop->run(); });
}

LiveServer::~LiveServer() {
  loop_->stopping = true;
  shared_->wake();
  loop_->thread.join();
  for (Loop::Connection& connection : loop_->connections) close(connection.fd);
  close(loop_->listen_fd);
  close(shared_->wake_fd);
}

std::string LiveServer::url() const { return "http://127.0.0.1:" + std::to_string(port_) + "/?token=" + token_; }

std::vector<LiveInbound> LiveServer::take_inbound() {
  std::vector<LiveInbound> taken;
  bool was_full = false;
  {
    const std::lock_guard<std::mutex> lock(shared_->mutex);
    for (auto client = shared_->clients.begin(); client != shared_->clients.end();) {
      std::deque<LiveInbound>& queue = client->second.inbound;
      was_full = was_full || queue.size() >= kInboundPerClient;
      bool closed = false;
      for (std::size_t k = 0; k < kTakePerClient && !queue.empty(); ++k) {
        closed = queue.front().closed;
        taken.push_back(std::move(queue.front()));
        queue.pop_front();
      }
      client = closed ? shared_->clients.erase(client) : std::next(client);
    }
  }
  if (was_full) shared_->wake();  // the server reads again from a client it had stopped reading
  return taken;
}

void LiveServer::wait_inbound(double seconds) {
  std::unique_lock<std::mutex> lock(shared_->mutex);
  if (seconds <= 0.0) return;
  for (const auto& [id, client] : shared_->clients) {
    if (!client.inbound.empty()) return;
  }
  shared_->inbound_ready.wait_for(lock, std::chrono::duration<double>(seconds));
}

void LiveServer::send_text(int client, const std::string& text) {
  const std::string framed = websocket_frame(kOpText, text.data(), text.size());
  {
    const std::lock_guard<std::mutex> lock(shared_->mutex);
    for (auto& [id, entry] : shared_->clients) {
      if ((client >= 0 && id != client) || entry.gone || entry.evict) continue;
      entry.texts.push_back(framed);
      entry.text_bytes += framed.size();
    }
  }
  shared_->wake();
}

std::vector<int> LiveServer::ready_clients() {
  const std::lock_guard<std::mutex> lock(shared_->mutex);
  std::vector<int> ready;
  for (const auto& [id, entry] : shared_->clients) {
    if (!entry.gone && !entry.evict && entry.in_flight < kFramesInFlight) ready.push_back(id);
  }
  return ready;
}

void LiveServer::send_frame(int client, const std::string& text, const std::vector<float>& frame) {
  std::string framed = websocket_frame(kOpText, text.data(), text.size());
  framed += websocket_frame(kOpBinary, reinterpret_cast<const char*>(frame.data()), frame.size() * sizeof(float));
  {
    const std::lock_guard<std::mutex> lock(shared_->mutex);
    const auto found = shared_->clients.find(client);
    if (found == shared_->clients.end() || found->second.gone) return;
    found->second.frame = std::move(framed);
    ++found->second.in_flight;
  }
  shared_->wake();
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

void LiveServer::Loop::run() {
  std::vector<pollfd> polled;
  std::vector<std::list<Connection>::iterator> polled_connections;
  while (!stopping) {
    polled.clear();
    polled_connections.clear();
    polled.push_back({shared->wake_fd, POLLIN, 0});
    polled.push_back({listen_fd, POLLIN, 0});
    for (auto connection = connections.begin(); connection != connections.end(); ++connection) {
      fill(*connection);
      short events = 0;
      // A client whose queue is full is not read: TCP holds its messages back, the other clients go on.
      if (connection->in.size() < 65536 && connection->state != State::kClosing) events |= POLLIN;
      if (connection->out_at < connection->out.size()) events |= POLLOUT;
      polled.push_back({connection->fd, events, 0});
      polled_connections.push_back(connection);
    }
    if (poll(polled.data(), static_cast<nfds_t>(polled.size()), 100) < 0 && errno != EINTR) break;
    if (polled[0].revents & POLLIN) {
      std::uint64_t count = 0;
      if (read(shared->wake_fd, &count, sizeof count) < 0) { /* nothing to read: a spurious wake */ }
    }
    const Clock::time_point now = Clock::now();
    for (std::size_t i = 0; i < polled_connections.size(); ++i) {
      const auto connection = polled_connections[i];
      const short revents = polled[i + 2].revents;
      if ((revents & (POLLERR | POLLNVAL)) != 0) {
        close_connection(connection, "");
        continue;
      }
      if ((revents & (POLLIN | POLLHUP)) != 0 && !read_some(*connection, now)) {
        close_connection(connection, "");
        continue;
      }
      if (connection->state == State::kRequest) handle_request(*connection, now);
      if (connection->state == State::kSocket) handle_frames(*connection, now);
      fill(*connection);
      if (!write_some(*connection, now)) close_connection(connection, "");
    }
    // After the round, never before it: a new comer may close the oldest pending connection, which the
    // round would have touched after its closing (a use after free).
    if (polled[1].revents & POLLIN) accept_new(now);
    // Deadlines, and what the loop's side asked (an eviction, a client whose outbox overflowed).
    for (auto connection = connections.begin(); connection != connections.end();) {
      const auto next = std::next(connection);
      const bool waiting = connection->out_at < connection->out.size();
      bool evict = false;
      // Every byte queued toward it but its frames (the newest replaces the one waiting: they cannot pile up).
      std::size_t queued = connection->out.size() - connection->out_at - std::min(connection->out_frame, connection->out.size() - connection->out_at);
      if (connection->state == State::kSocket) {
        const std::lock_guard<std::mutex> lock(shared->mutex);
        const Shared::Client& client = shared->clients[connection->client];
        evict = client.evict;
        queued += client.text_bytes + (connection->pong_due ? connection->pong.size() + 2 : 0);
      }
      const std::string id = "page " + std::to_string(connection->client);
      if (connection->state == State::kRequest && since(connection->opened, now) > kRequestSeconds) {
        close_connection(connection, "");  // silent or slow: its slot goes to the next one
      } else if (connection->state == State::kClosing && (!waiting || since(connection->progress, now) > 2.0)) {
        close_connection(connection, "");
      } else if (connection->state == State::kSocket) {
        if (evict) {
          close_connection(connection, "live: " + id + " closed: a new page came and it was heard from least recently");
        } else if (queued > kOutboxBytes) {
          close_connection(connection, "live: " + id + " dropped: over " + std::to_string(kOutboxBytes >> 20) +
                                           " MB waiting for it (it reads too little of what it asks for)");
        } else if (waiting && since(connection->progress, now) > kStalledSeconds) {
          close_connection(connection, "live: " + id + " dropped: it took nothing off its socket for " +
                                           std::to_string(int(kStalledSeconds)) + " s");
        } else if (since(connection->heard, now) > kSilentSeconds) {
          close_connection(connection, "live: " + id + " dropped: silent for " + std::to_string(int(kSilentSeconds)) +
                                           " s (not even a pong)");
        } else if (since(connection->pinged, now) > kPingSeconds && !waiting) {
          connection->pinged = now;
          connection->out = websocket_frame(kOpPing, "", 0);
          connection->out_at = 0;
          connection->out_frame = 0;
        }
      }
      connection = next;
    }
  }
}

void LiveServer::Loop::accept_new(Clock::time_point now) {
  for (int k = 0; k < 64; ++k) {
    const int fd = accept4(listen_fd, nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC);
    if (fd < 0) return;
    const int yes = 1;
    // A frame is two writes (its status, then its data): with Nagle's algorithm the second waited for the page's delayed ACK.
    setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &yes, sizeof yes);
    int pending = 0;
    auto oldest = connections.end();
    for (auto connection = connections.begin(); connection != connections.end(); ++connection) {
      if (connection->state != State::kSocket) {
        ++pending;
        if (oldest == connections.end() || connection->opened < oldest->opened) oldest = connection;
      }
    }
    if (pending >= kMaxPending) close_connection(oldest, "");  // the newest comer gets the slot: a reload always can
    Connection connection;
    connection.fd = fd;
    connection.opened = connection.heard = connection.progress = connection.pinged = now;
    connections.push_back(std::move(connection));
  }
}

bool LiveServer::Loop::read_some(Connection& connection, Clock::time_point now) {
  char buffer[65536];
  for (int k = 0; k < 4; ++k) {
    const std::size_t room = connection.skip > 0 ? sizeof buffer : std::min(sizeof buffer, 65536 - std::min<std::size_t>(connection.in.size(), 65536));
    if (room == 0) return true;
    const ssize_t got = recv(connection.fd, buffer, room, MSG_DONTWAIT);
    if (got == 0) return false;
    if (got < 0) return errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR;
    if (connection.state == State::kSocket) connection.heard = now, connection.spoke = true;
    std::size_t used = 0;
    const std::size_t size = static_cast<std::size_t>(got);
    if (connection.skip > 0 && connection.in.empty()) {  // a refused payload: discarded as it comes, never kept
      used = static_cast<std::size_t>(std::min<std::uint64_t>(connection.skip, size));
      connection.skip -= used;
    }
    connection.in.append(buffer + used, size - used);
    if (size < room) return true;
  }
  return true;
}

void LiveServer::Loop::refuse(Connection& connection, int code, const char* reason, const std::string& body,
                              const std::string& line) {
  if (!line.empty()) live_log(line);
  connection.out = http_answer(code, reason, body + "\n");
  connection.out_at = 0;
  connection.state = State::kClosing;
  connection.in.clear();
}

void LiveServer::Loop::handle_request(Connection& connection, Clock::time_point now) {
  const std::size_t end = connection.in.find("\r\n\r\n");
  // Over the cap however it came: still coming, or whole in one write (a 60 kB head used to be served).
  if (end == std::string::npos ? connection.in.size() > kRequestCap : end + 4 > kRequestCap) {
    return refuse(connection, 431, "Request Header Fields Too Large", "live: a request head over 8 KiB", "");
  }
  if (end == std::string::npos) return;
  const std::string head = connection.in.substr(0, end);
  connection.in.erase(0, end + 4);
  std::map<std::string, std::string> headers;
  std::string repeated;  // a header this server reads, given twice (which one counts is anybody's guess)
  std::size_t line_end = head.find("\r\n");
  const std::string request_line = head.substr(0, line_end);
  while (line_end != std::string::npos) {
    const std::size_t start = line_end + 2;
    line_end = head.find("\r\n", start);
    const std::string line = head.substr(start, line_end == std::string::npos ? std::string::npos : line_end - start);
    const std::size_t colon = line.find(':');
    if (colon == std::string::npos) continue;
    std::string value = line.substr(colon + 1);
    value.erase(0, std::min(value.find_first_not_of(" \t"), value.size()));
    value.erase(value.find_last_not_of(" \t") + 1);
    const std::string name = lower(line.substr(0, colon));
    const bool read = name == "host" || name == "origin" || name == "upgrade" || name.rfind("sec-websocket-", 0) == 0;
    if (!headers.emplace(name, value).second && read) repeated = name;
  }
  const std::size_t space = request_line.find(' ');
  const std::size_t space2 = request_line.find(' ', space == std::string::npos ? 0 : space + 1);
  if (space == std::string::npos || space2 == std::string::npos) return refuse(connection, 400, "Bad Request", "live: a malformed request", "");
  const std::string method = request_line.substr(0, space), target = request_line.substr(space + 1, space2 - space - 1);
  const std::size_t question = target.find('?');
  const std::string path = target.substr(0, question);
  const std::string query = question == std::string::npos ? std::string() : target.substr(question + 1);
  if (method != "GET") return refuse(connection, 405, "Method Not Allowed", "live: only GET", "");
  if (!repeated.empty()) {
    return refuse(connection, 400, "Bad Request", "live: a header given twice (" + shown(repeated) + ")",
                  "live: a request with two " + shown(repeated) + " headers, refused (400)");
  }
  const auto host = headers.find("host");
  if (host == headers.end()) return refuse(connection, 400, "Bad Request", "live: a request without Host", "");
  if (!live_host_allowed(host->second, server->port())) {
    return refuse(connection, 403, "Forbidden", "live: a request for another host",
                  "live: a request for the host '" + shown(host->second) + "', refused (403)");
  }
  if (path != "/" && path != "/ws") return refuse(connection, 404, "Not Found", "live: not found (the page is /?token=...)", "");
  const bool upgrade = lower(headers["upgrade"]) == "websocket";
  if (!live_token_matches(question == std::string::npos ? std::nullopt : std::optional<std::string>(query), server->token())) {
    return refuse(connection, 403, "Forbidden", "live: wrong or missing token (open the URL the program printed)",
                  path == "/" && !upgrade ? "live: a request for the page without the run's token, refused (403)"
                                          : "live: a WebSocket without the run's token, refused (403)");
  }
  if (path == "/") {
    connection.out = "HTTP/1.1 200 OK\r\nContent-Type: text/html; charset=utf-8\r\nContent-Length: " +
                     std::to_string(page.size()) + "\r\nCache-Control: no-store\r\nConnection: close\r\n\r\n" + page;
    connection.out_at = 0;
    connection.state = State::kClosing;
    connection.progress = now;
    return;
  }
  const auto origin = headers.find("origin");
  if (!live_origin_allowed(origin == headers.end() ? std::nullopt : std::optional<std::string>(origin->second), server->port())) {
    return refuse(connection, 403, "Forbidden", "live: a WebSocket from a foreign Origin",
                  "live: a WebSocket from the foreign Origin '" + shown(origin->second) + "', refused (403)");
  }
  if (!upgrade || headers["sec-websocket-key"].empty() || headers["sec-websocket-version"] != "13") {
    return refuse(connection, 400, "Bad Request", "live: /ws is a WebSocket (version 13)", "");
  }
  {
    const std::lock_guard<std::mutex> lock(shared->mutex);
    int open = 0, quietest = 0;
    for (const auto& [id, client] : shared->clients) open += client.gone || client.evict ? 0 : 1;
    if (open >= kMaxClients) {
      // A reload or a new tab always connects: the oldest of the clients that never said a word makes
      // room, else the one heard from least recently.
      auto rank = [](const Connection& other) { return std::make_pair(other.spoke, other.heard); };
      const Connection* quiet = nullptr;
      for (const Connection& other : connections) {
        if (other.state == State::kSocket && !shared->clients[other.client].evict && (quiet == nullptr || rank(other) < rank(*quiet))) {
          quiet = &other;
        }
      }
      quietest = quiet == nullptr ? 0 : quiet->client;
      if (quietest != 0) shared->clients[quietest].evict = true;
    }
    connection.client = shared->next_client++;
    Shared::Client& client = shared->clients[connection.client];
    client.inbound.push_back(LiveInbound{connection.client, {}, false, true});
  }
  shared->inbound_ready.notify_one();
  connection.out = "HTTP/1.1 101 Switching Protocols\r\nUpgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Accept: " +
                   websocket_accept(headers["sec-websocket-key"]) + "\r\n\r\n";
  connection.out_at = 0;
  connection.state = State::kSocket;
  connection.heard = connection.progress = connection.pinged = now;
  // The kernel's own queue for a WebSocket is bounded too (Linux would let it grow to 4 MB): a client
  // that reads nothing fills it within a second or two and is dropped 5 s later.
  const int queue = 256 << 10;
  setsockopt(connection.fd, SOL_SOCKET, SO_SNDBUF, &queue, sizeof queue);
}

// A line refusing a client's message: to that client (as the loop's refusals are) and to stderr.
void LiveServer::Loop::to_client(Connection& connection, const std::string& line) {
  live_log(line);
  const std::string text = error_message(line);
  const std::lock_guard<std::mutex> lock(shared->mutex);
  Shared::Client& client = shared->clients[connection.client];
  client.texts.push_back(websocket_frame(kOpText, text.data(), text.size()));
  client.text_bytes += client.texts.back().size();
}

void LiveServer::Loop::handle_frames(Connection& connection, Clock::time_point now) {
  bool pushed = false;
  while (connection.state == State::kSocket) {
    if (connection.skip > 0) {
      const std::size_t dropped = static_cast<std::size_t>(std::min<std::uint64_t>(connection.skip, connection.in.size()));
      connection.in.erase(0, dropped);
      connection.skip -= dropped;
      if (connection.skip > 0) break;
    }
    const WebSocketHeader header = parse_websocket_header(connection.in.data(), connection.in.size());
    if (!header.complete) break;
    const std::string id = "page " + std::to_string(connection.client);
    if (header.bad || !header.masked || (header.opcode == kOpContinuation && !connection.in_message) ||
        ((header.opcode == kOpText || header.opcode == kOpBinary) && connection.in_message)) {
      live_log("live: " + id + " closed: a frame that breaks the WebSocket protocol (RFC 6455)");
      const char code[2] = {char(1002 >> 8), char(1002 & 0xff)};
      connection.out.append(websocket_frame(kOpClose, code, 2));
      connection.state = State::kClosing;
      connection.in.clear();
      break;
    }
    connection.heard = now;
    const bool control = (header.opcode & 0x8) != 0;
    if (control) {  // at most kControlsPerSecond, as its text is held to its queue: the rest wait in TCP
      if (since(connection.controls_since, now) >= 1.0) connection.controls_since = now, connection.controls = 0;
      if (connection.controls >= kControlsPerSecond) break;
    }
    const std::size_t had = connection.refusing ? 0 : connection.message.size();
    if (!control && (header.opcode == kOpBinary || connection.refusing || had + header.length > kLiveMessageCap)) {
      // Refused by its header: the payload is discarded as it arrives, never held.
      if (!connection.refusing) {
        to_client(connection, header.opcode == kOpBinary
                                  ? "live: a binary message, refused (a command is JSON text)"
                                  : "live: a message of " + std::string(had > 0 || !header.fin ? "at least " : "") +
                                        std::to_string(had + header.length) + " bytes (its header says so), over the cap of " +
                                        std::to_string(kLiveMessageCap) + "; not read");
      }
      connection.in.erase(0, header.size);
      connection.skip = header.length;
      connection.refusing = !header.fin;
      connection.in_message = !header.fin;
      connection.message.clear();
      continue;
    }
    if (connection.in.size() < header.size + header.length) break;  // at most the cap: wait for the rest
    if (!control) {
      const std::lock_guard<std::mutex> lock(shared->mutex);
      if (header.fin && shared->clients[connection.client].inbound.size() >= kInboundPerClient) break;  // read later
    }
    std::string payload = connection.in.substr(header.size, static_cast<std::size_t>(header.length));
    connection.in.erase(0, header.size + static_cast<std::size_t>(header.length));
    for (std::size_t i = 0; i < payload.size(); ++i) payload[i] = static_cast<char>(payload[i] ^ char(header.mask[i % 4]));
    if (header.opcode == kOpClose) {
      connection.out.append(websocket_frame(kOpClose, payload.data(), std::min<std::size_t>(payload.size(), 2)));
      connection.state = State::kClosing;
      break;
    }
    if (control) ++connection.controls;
    if (header.opcode == kOpPing) {  // answered when its socket has taken what it was given (fill)
      connection.pong = std::move(payload);
      connection.pong_due = true;
      continue;
    }
    if (header.opcode == kOpPong) continue;
    connection.message += payload;
    connection.in_message = !header.fin;
    if (!header.fin) continue;
    {
      const std::lock_guard<std::mutex> lock(shared->mutex);
      shared->clients[connection.client].inbound.push_back(LiveInbound{connection.client, std::move(connection.message), false, false});
    }
    connection.message.clear();
    pushed = true;
  }
  if (pushed) shared->inbound_ready.notify_one();
}

// The client's outbox into its socket's buffer, when that is empty: texts first, then the newest frame.
void LiveServer::Loop::fill(Connection& connection) {
  if (connection.state != State::kSocket) return;
  if (connection.out_at == connection.out.size()) connection.out.clear(), connection.out_at = 0, connection.out_frame = 0;
  if (!connection.out.empty()) return;
  if (connection.pong_due) connection.out = websocket_frame(kOpPong, connection.pong.data(), connection.pong.size());
  connection.pong_due = false;
  const std::lock_guard<std::mutex> lock(shared->mutex);
  Shared::Client& client = shared->clients[connection.client];
  for (std::string& text : client.texts) connection.out += text;
  client.texts.clear();
  client.text_bytes = 0;
  connection.out += client.frame;
  connection.out_frame = client.frame.size();
  client.frame.clear();
}

bool LiveServer::Loop::write_some(Connection& connection, Clock::time_point now) {
  while (connection.out_at < connection.out.size()) {
    const ssize_t put = send(connection.fd, connection.out.data() + connection.out_at, connection.out.size() - connection.out_at,
                             MSG_DONTWAIT | MSG_NOSIGNAL);
    if (put < 0) return errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR;
    connection.out_at += static_cast<std::size_t>(put);
    connection.progress = now;
  }
  connection.progress = now;
  return true;
}

void LiveServer::Loop::close_connection(std::list<Connection>::iterator connection, const std::string& why) {
  if (!why.empty()) live_log(why);
  if (connection->state == State::kSocket || connection->client != 0) {
    {
      const std::lock_guard<std::mutex> lock(shared->mutex);
      Shared::Client& client = shared->clients[connection->client];
      if (!client.gone) {
        client.gone = true;
        client.texts.clear();
        client.frame.clear();
        client.inbound.push_back(LiveInbound{connection->client, {}, true, false});
      }
    }
    shared->inbound_ready.notify_one();
  }
  close(connection->fd);
  connections.erase(connection);
}

}  // namespace cl
