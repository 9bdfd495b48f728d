"""A hostile local client against the live server, a part of ./course test's live check
(tools/cl/live_checks.py) and of ./course sanitize (docs/DESIGN.md §3, "The live mode").

check_hostile runs the cases of a hostile local client, each of which
once ended the run or grew it without bound: names cut inside a UTF-8
character, request heads the server must refuse, RFC answers to broken close
frames and header lines, control characters in a quoted name, 60 idle
sockets (./course sanitize runs them under ASan), a ping flood beside an
honest page, and SIGINT and the page's stop during a step of minutes."""

import base64
import json
import os
import socket
import statistics
import struct
import threading
import time
import urllib.request
from pathlib import Path

from .live_stress import PAGE_SECONDS, close_answer, frame, honest_frame, open_socket, read_messages, rss

# Each case below is named by what it sends; each broke the server before the fix it checks.

OUTBOX_BYTES = 1 << 20          # LiveServer::kOutboxBytes
PING_SECONDS = 4.0              # the ping flood's length
PING_RSS_BYTES = OUTBOX_BYTES + (10 << 20)  # the outbox cap plus a constant
PING_MIN_FPS = 50               # the honest page's median beside the ping flood
IDLE_SOCKETS = 60               # more than LiveServer::kMaxPending (32): the oldest are closed as new ones come
STOP_SECONDS = 1.0              # a stop during a step that takes forever ends the run within this


def ask(port, request, read_for=2.0):
    """Raw request bytes to the server; the first line of its answer ('' if none)."""
    with socket.create_connection(("127.0.0.1", port), timeout=read_for) as sock:
        sock.sendall(request)
        answer = b""
        try:
            while b"\r\n" not in answer and len(answer) < 4096:
                chunk = sock.recv(4096)
                if not chunk:
                    break
                answer += chunk
        except OSError:
            pass
    return answer.split(b"\r\n", 1)[0].decode("latin-1")


def cut_utf8_names(port, token):
    """A command, a key and a knob named 39 × 'a' + 'é': the 40-byte cut of an error line's quote falls
    inside the 'é'. Each must be answered with its error line (the program ran on; it used to exit 1)."""
    names = ["a" * 39 + "é"]
    messages = [{"cmd": names[0]}, {"cmd": "pause", names[0]: 1}, {"cmd": "set", "knob": names[0], "value": 1}]
    sock = open_socket(port, token)
    for message in messages:
        sock.sendall(frame(json.dumps(message, ensure_ascii=False).encode()))
    got = read_messages(sock, time.monotonic() + 3, lambda got: sum(m.get("type") == "error" for m in got) >= 3)
    sock.close()
    errors = [m["text"] for m in got if m.get("type") == "error"]
    if len(errors) != 3 or not all("a" * 39 + "'" in text for text in errors):
        return [f"names cut inside a UTF-8 character: answered {errors}, not three error lines quoting 39 × 'a'"]
    return []


def head_refusals(port, token):
    """A 60 kB request head in one write (431), a foreign Host (403), two Origin headers (400) and an
    Origin with a NUL inside (400: Beast's parser refuses the byte): each refused, where each used to be served."""
    host = f"127.0.0.1:{port}"
    ws = (f"GET /ws?token={token} HTTP/1.1\r\nHost: {host}\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
          f"Sec-WebSocket-Key: {base64.b64encode(os.urandom(16)).decode()}\r\nSec-WebSocket-Version: 13\r\n").encode()
    cases = [
        ("a 60 kB head in one write", "431",
         f"GET /?token={token} HTTP/1.1\r\nHost: {host}\r\nX-Pad: {'a' * 60_000}\r\n\r\n".encode()),
        ("Host: evil.example", "403", f"GET /?token={token} HTTP/1.1\r\nHost: evil.example:{port}\r\n\r\n".encode()),
        ("no Host", "400", f"GET /?token={token} HTTP/1.1\r\n\r\n".encode()),
        ("two Origin headers, a foreign one first", "400",
         ws + f"Origin: http://evil.example\r\nOrigin: http://{host}\r\n\r\n".encode()),
        ("an Origin with a NUL inside", "400", ws + f"Origin: http://{host}\0.evil.example\r\n\r\n".encode()),
    ]
    problems = []
    for name, code, request in cases:
        line = ask(port, request)
        if line.split(" ")[1:2] != [code]:
            problems.append(f"{name}: answered {line[:60]!r}, not {code}")
    return problems


def rfc_answers(port, token):
    """Close frames no client may send (codes 999, 1005 and 5000, a 1-byte body, a reason that is not
    UTF-8) answered by the server's close 1002; a folded header line and a space before a header's
    colon answered 400 (RFC 6455 §5.5.1, §7.4; RFC 7230 §3.2.4): each was once taken as it came."""
    problems = []
    bodies = [("close code 999", struct.pack(">H", 999)), ("close code 1005", struct.pack(">H", 1005)),
              ("close code 5000", struct.pack(">H", 5000)), ("a 1-byte close body", b"\x03"),
              ("a close reason not UTF-8", struct.pack(">H", 1000) + b"\xff\xfe")]
    for name, body in bodies:
        try:
            sock = open_socket(port, token)
            sock.sendall(frame(body, opcode=8))
            code = close_answer(sock)
            sock.close()
        except OSError as error:
            code = error
        if code != 1002:
            problems.append(f"{name}: the server's close answered {code}, not 1002")
    host = f"127.0.0.1:{port}"
    heads = [("a folded header line", f"GET /?token={token} HTTP/1.1\r\nHost: {host}\r\nX-A: a\r\n b\r\n\r\n"),
             ("'Host : evil.example'", f"GET /?token={token} HTTP/1.1\r\nHost : evil.example\r\n\r\n")]
    for name, request in heads:
        line = ask(port, request.encode())
        if line.split(" ")[1:2] != ["400"]:
            problems.append(f"{name}: answered {line[:60]!r}, not 400")
    return problems


HIDDEN = "\u009b\u0085\u202e\u2066\u2069\u2028\u2029"  # C1 (CSI, NEL), bidi, line and paragraph separators


def hidden_controls(port, token):
    """A command named with C1, bidi and separator characters: its error line shows each as '?', as a
    C0 control is (a U+009B reached the terminal as CSI; a U+202E reversed the rest of the line)."""
    sock = open_socket(port, token)
    sock.sendall(frame(json.dumps({"cmd": "a" + HIDDEN + "b"}, ensure_ascii=False).encode()))
    got = read_messages(sock, time.monotonic() + 3, lambda got: any(m.get("type") == "error" for m in got))
    sock.close()
    errors = [m["text"] for m in got if m.get("type") == "error"]
    if not errors or "'a" + "?" * len(HIDDEN) + "b'" not in errors[0] or any(c in errors[0] for c in HIDDEN):
        return [f"C1 and bidi controls in a name: answered {errors!r}, not 'a{'?' * len(HIDDEN)}b'"]
    return []


def idle_sockets(port, token):
    """IDLE_SOCKETS connections that never send a request (the server closes the oldest as new ones
    come: that closing read freed memory); then the page and a new WebSocket's hello within 2 s."""
    held, problems = [], []
    try:
        for _ in range(IDLE_SOCKETS):
            held.append(socket.create_connection(("127.0.0.1", port), timeout=5))
            time.sleep(0.002)  # each accepted on its own round of the server's loop, as they come
        time.sleep(0.2)
        start = time.monotonic()
        page = urllib.request.urlopen(f"http://127.0.0.1:{port}/?token={token}", timeout=5).read()
        sock = open_socket(port, token)
        hello = read_messages(sock, time.monotonic() + 5, lambda got: any(m.get("type") == "hello" for m in got))
        sock.close()
        if b"CLLive" not in page or not hello or time.monotonic() - start > PAGE_SECONDS:
            problems.append(f"{IDLE_SOCKETS} idle sockets: the page and a hello took {time.monotonic() - start:.2f} s "
                            f"(at most {PAGE_SECONDS})")
    except OSError as error:
        problems.append(f"{IDLE_SOCKETS} idle sockets: {error}")
    for sock in held:
        sock.close()
    return problems


def ping_flood(port, token, pid, bounded=True):
    """A client sends 125-byte pings as fast as the server takes them and reads 64 kB every 0.3 s,
    for PING_SECONDS, beside an honest page. The server's resident memory must rise at most the
    outbox cap plus 10 MB (it queued a pong per ping: +100 MB a second) and the honest page keep a
    median of PING_MIN_FPS frames a second (bounded=False: under ASan, neither is asked)."""
    import websocket  # Debian's python3-websocket
    problems, numbers = [], {}
    stop = threading.Event()
    flooder = open_socket(port, token)
    flooder.settimeout(10)
    pings = b"".join(frame(b"p" * 125, opcode=9) for _ in range(512))

    def send():
        try:
            while not stop.is_set():
                flooder.sendall(pings)
        except OSError:
            pass

    def read():
        while not stop.is_set():
            try:
                flooder.recv(65536)
            except OSError:
                return
            time.sleep(0.3)

    honest = websocket.create_connection(f"ws://127.0.0.1:{port}/ws?token={token}", timeout=5)
    before = peak = rss(pid)
    threads = [threading.Thread(target=send, daemon=True), threading.Thread(target=read, daemon=True)]
    for thread in threads:
        thread.start()
    bins = [0] * int(PING_SECONDS)
    start = time.monotonic()
    next_sample = start
    try:
        while time.monotonic() - start < PING_SECONDS:
            if time.monotonic() >= next_sample:
                peak, next_sample = max(peak, rss(pid)), next_sample + 0.1
            honest_frame(honest, start, bins, 0.05)
    except (OSError, websocket.WebSocketException) as error:
        problems.append(f"ping flood: the honest page lost its connection: {error}")
    peak = max(peak, rss(pid))
    stop.set()
    try:
        flooder.shutdown(socket.SHUT_RDWR)  # wakes the sender blocked in sendall
    except OSError:
        pass
    flooder.close()
    honest.close()
    for thread in threads:
        thread.join(timeout=5)
    numbers["ping_rss_rise_mb"] = (peak - before) / 2**20
    numbers["ping_honest_fps"] = statistics.median(bins)
    if bounded and peak - before > PING_RSS_BYTES:
        problems.append(f"ping flood: the server's resident memory rose {(peak - before) / 2**20:.1f} MB in "
                        f"{PING_SECONDS:.0f} s (at most {PING_RSS_BYTES / 2**20:.0f}: the outbox cap plus 10 MB)")
    if bounded and statistics.median(bins) < PING_MIN_FPS:
        problems.append(f"ping flood: the honest page's frames per second (1-s bins) were {bins}, median under "
                        f"{PING_MIN_FPS}")
    return problems, numbers


def stop_during_step(program, how, scratch, timeout=20, env=None, prefix=()):
    """`program --live --iterations 100000000` (a first step of minutes), stopped by `how` ("SIGINT" or
    the page's "stop") 0.5 s in: it must exit 0 within STOP_SECONDS with the summary written.
    Returns (problems, seconds, its stderr)."""
    import signal
    import subprocess
    import websocket  # Debian's python3-websocket
    from .live import read_url
    summary = Path(scratch) / f"summary-{how}.json"
    summary.unlink(missing_ok=True)
    process = subprocess.Popen([*prefix, str(program), "--scene", "curtain-16", "--live", "--iterations", "100000000",
                                "--summary", str(summary)], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               encoding="utf-8",
                               errors="replace", env=env)
    problems, seconds, err = [], None, ""
    try:
        port, token = read_url(process, timeout)
        client = websocket.create_connection(f"ws://127.0.0.1:{port}/ws?token={token}", timeout=5)
        time.sleep(0.5)  # the first step is well under way
        start = time.monotonic()
        if how == "SIGINT":
            process.send_signal(signal.SIGINT)
        else:
            client.send('{"cmd": "stop"}')
        try:
            code = process.wait(timeout=STOP_SECONDS + 4)
            seconds = time.monotonic() - start
        except subprocess.TimeoutExpired:
            code = None
        client.close()
        if code is None or seconds > STOP_SECONDS:
            problems.append(f"{how} during a 1e8-iteration step: the program ran on "
                            f"{'over 5' if code is None else f'{seconds:.2f}'} s (at most {STOP_SECONDS:.0f})")
        elif code != 0:
            problems.append(f"{how} during a 1e8-iteration step: exit {code}, not 0")
        elif not summary.is_file() or json.loads(summary.read_text(encoding="utf-8")).get("live") is not True:
            problems.append(f"{how} during a 1e8-iteration step: no summary written")
    except (RuntimeError, OSError, websocket.WebSocketException, ValueError) as error:
        problems.append(f"{how} during a 1e8-iteration step: {type(error).__name__}: {error}")
    finally:
        if process.poll() is None:
            process.kill()
        err = process.communicate()[1]
    return problems, seconds, err


def check_hostile(program, scratch, start_seconds=20, bounded=True, env=None, prefix=()):
    """Rounds 3 and 4's cases against `program --live` on a 16² curtain: names cut inside a UTF-8 character,
    the request heads the server must refuse, RFC answers, control characters in a name, 60 idle sockets, a ping flood beside an honest page; and,
    on two programs of their own at the same time, SIGINT and the page's stop during a 1e8-iteration
    step. Returns (problems, numbers), numbers["stderr"] the three programs' stderr. bounded=False (ASan):
    the flood's memory and rate are not asked; env, prefix: the programs' environment and the words
    before their command (nice)."""
    import signal
    import subprocess
    from .live import read_url
    stops = {}

    def stop(how):
        stops[how] = stop_during_step(program, how, scratch, start_seconds, env, prefix)

    stoppers = [threading.Thread(target=stop, args=(how,)) for how in ("SIGINT", "stop")]
    for thread in stoppers:
        thread.start()
    process = subprocess.Popen([*prefix, str(program), "--scene", "curtain-16", "--live"], stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, encoding="utf-8", errors="replace", env=env)
    problems, numbers = [], {}
    try:
        port, token = read_url(process, start_seconds)
        for case in (cut_utf8_names, head_refusals, rfc_answers, hidden_controls, idle_sockets):
            problems += case(port, token)
            if process.poll() is not None:
                problems.append(f"the program ended (exit {process.returncode}) at the case {case.__name__}")
                break
        else:
            flood_problems, numbers = ping_flood(port, token, process.pid, bounded)
            problems += flood_problems
            process.send_signal(signal.SIGTERM)
            if process.wait(timeout=5) != 0:
                problems.append(f"after SIGTERM the program exited {process.returncode}, not 0")
    except (RuntimeError, OSError, subprocess.TimeoutExpired, ValueError) as error:
        problems.append(f"{type(error).__name__}: {error}")
    finally:
        if process.poll() is None:
            process.kill()
            problems.append("the program did not end within 5 s of SIGTERM: killed")
        out, err = process.communicate()
    for thread in stoppers:
        thread.join(timeout=30)
    numbers["stderr"] = err
    if any(c in err for c in HIDDEN):
        problems.append("C1 or bidi controls reached stderr as themselves, not as '?'")
    for how in ("SIGINT", "stop"):
        stop_problems, numbers[f"{how}_seconds"], stop_err = stops.get(how, ([f"{how}: did not finish"], None, ""))
        problems += stop_problems
        numbers["stderr"] += stop_err
    return problems, numbers
