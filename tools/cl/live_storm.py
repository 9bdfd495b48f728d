"""Round 4's floods against the live server, a part of ./course test's live check
(tools/cl/live_checks.py; docs/DESIGN.md §3, "The live mode").

check_storm runs lab 04's reference live on a 16² curtain once, about 17 s,
beside an honest page that reads and acknowledges every frame:
TINY_SOCKETS sockets that each start a fragmented text message and stream
7-byte continuation frames (once the server spent its time on each frame's
bytes again); then a storm of STORM_RATE WebSocket opens a second for
STORM_SECONDS, each opened with the token and closed at once (once the run
built a hello for each and fell behind by minutes); then a second storm,
during which the honest page asks the run to stop. What must hold: the
honest page's frames per second (1-s bins) at least MIN_FPS beside the tiny
frames and in every second of the storm, at least MIN_FPS in the second after
it; the server's resident memory within STORM_RSS_BYTES of where it began;
the stop ending the run within STOP_SECONDS. The abusers run in processes of
their own (standard library sockets: they must misbehave), so that Python's
lock never slows the honest page (Debian's python3-websocket)."""
import base64
import multiprocessing
import os
import signal
import socket
import statistics
import subprocess
import time

from .live_stress import honest_frame, open_socket, rss

TINY_SOCKETS = 15
TINY_SECONDS = 3.0
STORM_RATE = 2000        # WebSocket opens a second
STORM_SECONDS = 10.0
MIN_FPS = 50
STORM_RSS_BYTES = 20 << 20
STOP_SECONDS = 1.0


def tiny_frames(port, token, seconds):
    """TINY_SOCKETS sockets, each a fragmented text message's first frame, then 7-byte continuation
    frames as fast as the server takes them; a socket the server closes is opened again."""
    tiny = memoryview((bytes([0x00, 0x80 | 7]) + b"\0\0\0\0" + b"aaaaaaa") * 512)  # not final, a zero mask
    end, sockets, sent = time.monotonic() + seconds, [None] * TINY_SOCKETS, [0] * TINY_SOCKETS
    while time.monotonic() < end:
        for k, sock in enumerate(sockets):
            try:
                if sock is None:
                    sock = sockets[k] = open_socket(port, token, timeout=1)
                    sock.sendall(bytes([0x01, 0x80 | 1]) + b"\0\0\0\0{")  # a text message begins, not final
                    sock.setblocking(False)
                    sent[k] = 0
                sent[k] = (sent[k] + sock.send(tiny[sent[k]:])) % len(tiny)  # whole frames, however it is cut
            except BlockingIOError:
                pass
            except OSError:
                if sock is not None:
                    sock.close()
                sockets[k] = None
                time.sleep(0.01)
    for sock in sockets:
        if sock is not None:
            sock.close()


def storm(port, token, rate, seconds, opens):
    """`rate` WebSocket opens a second for `seconds`: the handshake sent with the token, the socket
    closed as soon as the server answers (or at once, when the pace falls behind); `opens` (a shared
    counter) gets how many were made."""
    key = base64.b64encode(os.urandom(16)).decode()
    request = (f"GET /ws?token={token} HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nUpgrade: websocket\r\n"
               f"Connection: Upgrade\r\nSec-WebSocket-Key: {key}\r\nSec-WebSocket-Version: 13\r\n\r\n").encode()
    start, opened = time.monotonic(), 0
    while time.monotonic() < start + seconds:
        due = start + opened / rate
        time.sleep(max(0.0, due - time.monotonic()))
        try:
            with socket.create_connection(("127.0.0.1", port), timeout=1) as sock:
                sock.sendall(request)
                if time.monotonic() < due + 0.01:
                    sock.settimeout(0.005)
                    try:
                        sock.recv(256)
                    except OSError:
                        pass
        except OSError:
            pass
        opened += 1
    with opens.get_lock():
        opens.value += opened


class Honest:
    """One page that reads and acknowledges every frame, counting them per second."""

    def __init__(self, port, token, pid):
        import websocket  # Debian's python3-websocket
        self.client = websocket.create_connection(f"ws://127.0.0.1:{port}/ws?token={token}", timeout=5)
        self.pid, self.base_rss = pid, rss(pid)
        self.peak_rss = self.base_rss

    def frames(self, seconds):
        """Frames per 1-s bin for `seconds`; the server's peak memory sampled every 0.1 s."""
        bins, start, next_sample = [0] * int(round(seconds)), time.monotonic(), 0.0
        while time.monotonic() - start < seconds:
            if time.monotonic() - start >= next_sample:
                self.peak_rss, next_sample = max(self.peak_rss, rss(self.pid)), next_sample + 0.1
            honest_frame(self.client, start, bins, 0.05)
        return bins


CONTEXT = multiprocessing.get_context("fork" if hasattr(os, "fork") else "spawn")


def abuse(target, *args):
    """`target(*args)` in a process of its own, started."""
    process = CONTEXT.Process(target=target, args=args, daemon=True)
    process.start()
    return process


def check_storm(program):
    """The tiny frames, the storm and a stop during a storm against `program --live`; (problems, numbers)."""
    import websocket  # Debian's python3-websocket
    from .live import read_url
    process = subprocess.Popen([str(program), "--scene", "curtain-16", "--live"], stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, encoding="utf-8", errors="replace")
    problems, numbers, abusers = [], {}, []
    try:
        port, token = read_url(process, 20)
        honest = Honest(port, token, process.pid)
        honest.frames(1.0)  # settled
        abusers.append(abuse(tiny_frames, port, token, TINY_SECONDS))
        tiny = honest.frames(TINY_SECONDS)
        abusers[-1].join(timeout=5)
        numbers["tiny_fps"] = tiny
        if statistics.median(tiny) < MIN_FPS:
            problems.append(f"beside {TINY_SOCKETS} tiny-frame sockets the honest page's frames per second were "
                            f"{tiny}, median under {MIN_FPS}")
        opens = CONTEXT.Value("l", 0)
        abusers += [abuse(storm, port, token, STORM_RATE / 2, STORM_SECONDS, opens) for _ in range(2)]
        during = honest.frames(STORM_SECONDS)
        after = honest.frames(1.0)
        numbers.update(storm_fps=during, after_fps=after, rss_rise_mb=(honest.peak_rss - honest.base_rss) / 2**20)
        if min(during) < MIN_FPS:
            problems.append(f"during a storm of {STORM_RATE} WebSocket opens a second the honest page's frames per "
                            f"second were {during}, under {MIN_FPS}")
        if after[0] < MIN_FPS:
            problems.append(f"in the second after the storm the honest page got {after[0]} frames (at least {MIN_FPS})")
        if honest.peak_rss - honest.base_rss > STORM_RSS_BYTES:
            problems.append(f"during the storm the server's resident memory rose {numbers['rss_rise_mb']:.1f} MB "
                            f"(at most {STORM_RSS_BYTES >> 20})")
        for abuser in abusers:
            abuser.join(timeout=5)
        numbers["storm_rate"] = opens.value / STORM_SECONDS
        if opens.value < 0.9 * STORM_RATE * STORM_SECONDS:
            problems.append(f"the storm made {opens.value / STORM_SECONDS:.0f} opens a second, not {STORM_RATE}")
        abusers += [abuse(storm, port, token, STORM_RATE / 2, 3.0, opens) for _ in range(2)]
        honest.frames(1.0)
        start = time.monotonic()
        honest.client.send('{"cmd": "stop"}')
        try:
            code = process.wait(timeout=STOP_SECONDS + 4)
        except subprocess.TimeoutExpired:
            code = None
        numbers["stop_seconds"] = time.monotonic() - start
        if code != 0 or numbers["stop_seconds"] > STOP_SECONDS:
            problems.append(f"the page's stop during a storm: exit {code} after {numbers['stop_seconds']:.2f} s "
                            f"(0 within {STOP_SECONDS:.0f} s expected)")
        honest.client.close()
    except (RuntimeError, OSError, ValueError, websocket.WebSocketException) as error:
        problems.append(f"{type(error).__name__}: {error}")
    finally:
        for abuser in abusers:
            if abuser.is_alive():
                os.kill(abuser.pid, signal.SIGKILL)
            abuser.join(timeout=5)
        if process.poll() is None:
            process.kill()
            problems.append("the program did not end: killed")
        err = process.communicate()[1]
    numbers["stderr_lines"] = len(err.splitlines())
    return problems, numbers
