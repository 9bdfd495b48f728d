"""The live mode's server under an unfriendly pace, a part of ./course test's
live check (tools/cl/live_checks.py; docs/DESIGN.md §3, "The live mode").
Against lab 04's reference live on a 16² curtain, for about 12 s: three
clients acknowledge frames every 4 ms and never read them, a fourth sends
10,000 refused messages as fast as it can (and reads its answers only at the
end), 50 sockets are opened and held (25 WebSockets with the token that
never read, 25 TCP connections that never send a request), and one message
declares 100 MB. Meanwhile an honest client reads and acknowledges every
frame and sends a refused message twice a second. What must hold: the honest
client's median frames per second (1-s bins over 10 s) at least 20, and an
answer to each of its refused messages; with the 50 sockets held, the page
served and a new WebSocket greeted within 2 s; the 100 MB message refused by
its header (its sender closed with 1009, RFC 6455's "message too big") with
the server's resident memory rising less than 10 MB while it comes; every answer the flood asked for given. Standard
library sockets for the abusers (they must misbehave), Debian's
python3-websocket for the honest client. All traffic to 127.0.0.1; every loop
is bounded in count and time."""
import base64
import json
import os
import socket
import statistics
import struct
import threading
import time
import urllib.request

SECONDS = 10.0          # the honest client's measurement
MIN_FPS = 20            # its median frames per second
HELD_SOCKETS = 50
PAGE_SECONDS = 2.0
BIG_BYTES = 100 << 20
RSS_RISE_BYTES = 10 << 20
FLOOD = 10_000


def frame(payload, opcode=1, mask=None):
    """A client's (masked) WebSocket frame around `payload` (bytes)."""
    mask = os.urandom(4) if mask is None else mask
    size = len(payload)
    head = bytes([0x80 | opcode])
    if size < 126:
        head += bytes([0x80 | size])
    elif size < 65536:
        head += bytes([0x80 | 126]) + struct.pack(">H", size)
    else:
        head += bytes([0x80 | 127]) + struct.pack(">Q", size)
    if mask == b"\0\0\0\0":
        return head + mask + payload
    return head + mask + bytes(b ^ mask[i % 4] for i, b in enumerate(payload))


def open_socket(port, token, timeout=5.0):
    """A raw WebSocket with the token, the server's 101 read (and nothing else)."""
    sock = socket.create_connection(("127.0.0.1", port), timeout=timeout)
    key = base64.b64encode(os.urandom(16)).decode()
    sock.sendall(f"GET /ws?token={token} HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nUpgrade: websocket\r\n"
                 f"Connection: Upgrade\r\nSec-WebSocket-Key: {key}\r\nSec-WebSocket-Version: 13\r\n\r\n".encode())
    head = b""
    while not head.endswith(b"\r\n\r\n") and len(head) < 4096:
        byte = sock.recv(1)
        if not byte:
            raise OSError("the server closed the connection during the handshake")
        head += byte
    if not head.startswith(b"HTTP/1.1 101"):
        raise OSError(f"handshake answered {head.splitlines()[0]!r}")
    return sock


def read_messages(sock, until, want):
    """Text messages from a raw socket until want(messages) holds or `until` (monotonic) passes."""
    buffer, messages = b"", []
    while time.monotonic() < until and not want(messages):
        sock.settimeout(max(0.01, until - time.monotonic()))
        try:
            chunk = sock.recv(1 << 16)
        except (socket.timeout, OSError):
            break
        if not chunk:
            break
        buffer += chunk
        while len(buffer) >= 2:
            size, at = buffer[1] & 0x7f, 2
            if size == 126:
                size, at = struct.unpack(">H", buffer[2:4])[0] if len(buffer) >= 4 else -1, 4
            elif size == 127:
                size, at = struct.unpack(">Q", buffer[2:10])[0] if len(buffer) >= 10 else -1, 10
            if size < 0 or len(buffer) < at + size:
                break
            if buffer[0] & 0x0f == 1:
                messages.append(json.loads(buffer[at:at + size]))
            buffer = buffer[at + size:]
    return messages


def close_answer(sock, seconds=3.0):
    """The code of the server's close frame on a raw WebSocket (None: it closed without one, or never)."""
    buffer, end = b"", time.monotonic() + seconds
    while time.monotonic() < end:
        while len(buffer) >= 2:
            size, at = buffer[1] & 0x7f, 2
            if size == 126:
                size, at = (struct.unpack(">H", buffer[2:4])[0] if len(buffer) >= 4 else -1), 4
            elif size == 127:
                size, at = (struct.unpack(">Q", buffer[2:10])[0] if len(buffer) >= 10 else -1), 10
            if size < 0 or len(buffer) < at + size:
                break
            if buffer[0] & 0x0f == 8:
                return struct.unpack(">H", buffer[at:at + 2])[0] if size >= 2 else None
            buffer = buffer[at + size:]
        sock.settimeout(max(0.01, end - time.monotonic()))
        try:
            chunk = sock.recv(1 << 16)
        except OSError:
            return None
        if not chunk:
            return None
        buffer += chunk
    return None


def rss(pid):
    with open(f"/proc/{pid}/status", encoding="utf-8") as status:
        for line in status:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) * 1024
    return 0


def honest_frame(client, start, bins, timeout):
    """One message from an honest page's socket within `timeout` (None: none
    came): a frame is counted in its second's bin since `start` and acknowledged,
    as the page does."""
    import websocket  # Debian's python3-websocket

    client.settimeout(timeout)
    try:
        message = client.recv()
    except websocket.WebSocketTimeoutException:
        return None
    if isinstance(message, bytes):
        at = int(time.monotonic() - start)
        if at < len(bins):
            bins[at] += 1
        client.send('{"cmd": "ack"}')
    return message


class Stress:
    def __init__(self, port, token, pid):
        self.port, self.token, self.pid = int(port), token, pid
        self.stop = threading.Event()
        self.problems, self.numbers = [], {}
        self.lock = threading.Lock()

    def problem(self, text):
        with self.lock:
            self.problems.append(text)

    def acker(self):
        """Acknowledges every 4 ms and never reads (until dropped, or the end)."""
        start = time.monotonic()
        try:
            sock = open_socket(self.port, self.token)
            while time.monotonic() < start + SECONDS and not self.stop.is_set():
                sock.sendall(frame(b'{"cmd": "ack"}'))
                time.sleep(0.004)
        except OSError:  # dropped by the server: what it should do (after its outbox stalled 5 s)
            with self.lock:
                self.numbers.setdefault("ackers_dropped_after", []).append(round(time.monotonic() - start, 1))

    def flooder(self):
        """FLOOD refused messages at once, its answers read only afterwards: all must come."""
        try:
            data = b"".join(frame(b'{"cmd": "flood", "n": %d}' % k if k % 2 else b'{"cmd": "pause"') for k in range(FLOOD))
            sock = open_socket(self.port, self.token, timeout=10)  # then at once: a silent new client may be evicted
            sock.sendall(data)
            errors = read_messages(sock, time.monotonic() + 8,
                                   lambda got: sum(m.get("type") == "error" for m in got) >= FLOOD)
            answered = sum(m.get("type") == "error" for m in errors)
            self.numbers["flood_answered"] = answered
            if answered != FLOOD:
                self.problem(f"the flooding client got {answered} answers to its {FLOOD} refused messages")
            sock.close()
        except OSError as error:
            self.problem(f"the flooding client: {error}")

    def big_message(self):
        """A frame declaring 100 MB: refused by its header (close 1009), the payload never held."""
        try:
            sock = open_socket(self.port, self.token, timeout=10)
            before = peak = rss(self.pid)
            sock.sendall(bytes([0x81, 0x80 | 127]) + struct.pack(">Q", BIG_BYTES) + b"\0" * 4)  # a zero mask
            chunk = b"\0" * (1 << 20)
            try:
                for _ in range(BIG_BYTES >> 20):
                    sock.sendall(chunk)
                    peak = max(peak, rss(self.pid))
            except OSError:
                pass  # the server closed it: its close frame says why
            code = close_answer(sock)
            peak = max(peak, rss(self.pid))
            self.numbers["rss_rise_mb"] = (peak - before) / 2**20
            if peak - before >= RSS_RISE_BYTES:
                self.problem(f"a 100 MB message raised the server's resident memory by {(peak - before) / 2**20:.1f} MB "
                             f"(at most {RSS_RISE_BYTES >> 20} MB)")
            if code != 1009:
                self.problem(f"the 100 MB message's sender was closed with {code}, not 1009 (message too big)")
            sock.close()
        except OSError as error:
            self.problem(f"the 100 MB message: {error}")

    def held_sockets(self):
        """50 sockets held; the page and a new WebSocket must still be served within PAGE_SECONDS."""
        held = []
        try:
            for k in range(HELD_SOCKETS):
                if k % 2:
                    held.append(socket.create_connection(("127.0.0.1", self.port), timeout=5))
                else:
                    held.append(open_socket(self.port, self.token))
        except OSError as error:
            self.problem(f"opening {HELD_SOCKETS} sockets: {error} after {len(held)}")
        try:
            start = time.monotonic()
            page = urllib.request.urlopen(f"http://127.0.0.1:{self.port}/?token={self.token}", timeout=10).read()
            loaded = time.monotonic() - start
            sock = open_socket(self.port, self.token, timeout=10)
            hello = read_messages(sock, time.monotonic() + 10, lambda got: any(m.get("type") == "hello" for m in got))
            greeted = time.monotonic() - start
            sock.close()
            self.numbers["page_seconds"], self.numbers["hello_seconds"] = loaded, greeted
            if b"CLLive" not in page or loaded > PAGE_SECONDS:
                self.problem(f"with {len(held)} sockets held the page took {loaded:.2f} s (at most {PAGE_SECONDS} s)")
            if not hello or greeted > PAGE_SECONDS:
                self.problem(f"with {len(held)} sockets held a new WebSocket was greeted after {greeted:.2f} s "
                             f"(at most {PAGE_SECONDS} s)")
        except OSError as error:
            self.problem(f"with {len(held)} sockets held the page or a new WebSocket failed: {error}")
        self.stop.wait(SECONDS)
        for sock in held:
            sock.close()

    def honest(self):
        """Reads and acknowledges every frame; a refused message twice a second, each answered."""
        import websocket  # Debian's python3-websocket
        try:
            client = websocket.create_connection(f"ws://127.0.0.1:{self.port}/ws?token={self.token}", timeout=5)
        except (OSError, websocket.WebSocketException) as error:
            return self.problem(f"the honest client could not connect: {error}")
        bins, asked, answered = [0] * int(SECONDS), 0, 0
        start = time.monotonic()
        next_ask = start + 0.25
        try:
            while time.monotonic() - start < SECONDS + 2 and (time.monotonic() - start < SECONDS or answered < asked):
                if time.monotonic() >= next_ask and time.monotonic() - start < SECONDS:
                    client.send(json.dumps({"cmd": "honest-mistake", "n": asked}))
                    asked, next_ask = asked + 1, next_ask + 0.5
                message = honest_frame(client, start, bins, 0.1)
                if isinstance(message, str) and json.loads(message).get("type") == "error":
                    answered += 1
        except (OSError, websocket.WebSocketException) as error:
            self.problem(f"the honest client lost its connection: {error}")
        client.close()
        self.numbers["honest_fps"], self.numbers["honest_bins"] = statistics.median(bins), bins
        self.numbers["honest_answered"] = f"{answered}/{asked}"
        if statistics.median(bins) < MIN_FPS:
            self.problem(f"the honest client's frames per second (1-s bins) were {bins}: median "
                         f"{statistics.median(bins)}, under {MIN_FPS}")
        if answered != asked:
            self.problem(f"the honest client got {answered} answers to its {asked} refused messages")

    def run(self):
        """Everything at once; returns (problems, numbers)."""
        honest = threading.Thread(target=self.honest)
        honest.start()
        time.sleep(0.5)
        abusers = [threading.Thread(target=self.acker) for _ in range(3)]
        abusers += [threading.Thread(target=self.flooder), threading.Thread(target=self.held_sockets),
                    threading.Thread(target=self.big_message)]
        for thread in abusers:
            thread.start()
        honest.join(timeout=SECONDS + 10)
        self.stop.set()
        for thread in abusers:
            thread.join(timeout=15)
        if honest.is_alive() or any(thread.is_alive() for thread in abusers):
            self.problem("a client of the stress test did not finish in time")
        if len(self.numbers.get("ackers_dropped_after", [])) != 3:
            self.problem(f"of the 3 clients that never read, {len(self.numbers.get('ackers_dropped_after', []))} were "
                         f"dropped within {SECONDS:.0f} s")
        return self.problems, self.numbers


def problem_and_reset(port, token):
    """A drag 1000 m away makes the run unstable (strain over 1000): a page opened then is greeted with
    the problem and the last good frame, and reset alone makes the run go on. Returns what went wrong."""
    import websocket  # Debian's python3-websocket

    def statuses(client, seconds):
        """(text messages, status of each frame) until `seconds` pass; every frame acknowledged."""
        end, texts, status = time.monotonic() + seconds, [], None
        while time.monotonic() < end:
            client.settimeout(max(0.01, end - time.monotonic()))
            try:
                message = client.recv()
            except websocket.WebSocketTimeoutException:
                break
            if isinstance(message, bytes):
                client.send('{"cmd": "ack"}')
                yield texts, status
            else:
                texts.append(json.loads(message))
                status = texts[-1] if texts[-1].get("type") == "frame" else status

    url = f"ws://127.0.0.1:{port}/ws?token={token}"
    first = websocket.create_connection(url, timeout=5)
    for texts, status in statuses(first, 3):
        break
    else:
        return ["problem and reset: the first client got no frame"]
    particle = max(p for p in range(texts[0]["particles"]) if p not in status["pinned"])
    first.send(json.dumps({"cmd": "drag", "particle": particle, "x": [1000, 0, 0]}))
    problems = ["problem and reset: a drag 1000 m away did not stop the run within 3 s"]
    for texts, status in statuses(first, 3):
        if status and status["problem"] and status["paused"]:
            problems = []
            break
    late = websocket.create_connection(url, timeout=5)
    for texts, status in statuses(late, 3):
        if status:
            break
    kinds = [m.get("type") for m in texts]
    if kinds[:2] != ["hello", "problem"] or not status or not status["problem"]:
        problems.append(f"problem and reset: a page opened after the problem got {kinds[:3]} "
                        f"(the hello, the problem, a frame showing it expected)")
    first.send('{"cmd": "reset"}')
    for texts, status in statuses(first, 3):
        if status and status["frame"] >= 10 and not status["paused"] and not status["problem"]:
            break
    else:
        problems.append(f"problem and reset: after reset the run did not go on by itself (last status "
                        f"frame {status and status['frame']}, paused {status and status['paused']})")
    first.close()
    late.close()
    return problems


def check_stress(program):
    """Runs the stress against `program --live` on a 16² curtain; (problems, numbers)."""
    import signal
    import subprocess
    from .live import read_url
    process = subprocess.Popen([str(program), "--scene", "curtain-16", "--live"], stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, encoding="utf-8", errors="replace")
    problems, numbers = [], {}
    try:
        port, token = read_url(process, 20)
        problems, numbers = Stress(port, token, process.pid).run()
        problems += problem_and_reset(port, token)
        start = time.monotonic()
        process.send_signal(signal.SIGTERM)
        code = process.wait(timeout=5)
        numbers["sigterm_seconds"] = time.monotonic() - start
        if code != 0:
            problems.append(f"after SIGTERM the program exited {code}, not 0")
    except (RuntimeError, OSError, subprocess.TimeoutExpired, ValueError) as error:
        problems.append(f"{type(error).__name__}: {error}")
    finally:
        if process.poll() is None:
            process.kill()
            problems.append("the program did not end within 5 s of SIGTERM: killed")
        out, err = process.communicate()
    lines = err.splitlines()
    numbers["stderr_lines"] = len(lines)
    numbers["dropped"] = [line for line in lines if " dropped" in line or " closed" in line]
    if len(lines) > 200:
        problems.append(f"{len(lines)} lines on stderr (a rate-limited summary expected): {lines[-3:]}")
    return problems, numbers
