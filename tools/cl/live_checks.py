"""The live mode in a real browser, a check of ./course test (docs/DESIGN.md
§3, "The live mode"): lab 04's reference runs live on a 16² curtain, headless
Chromium opens its page, and the check drives the page through Chromium's
DevTools protocol (Debian's python3-websocket), so that real pointer events
reach it: a drag of the bottom-left particle by 0.2 m (the simulation's own
status says where it holds it, and its neighbour follows), K turned in the
page's control (the next frames are stepped with it), a malformed message (the
error line, and frames keep coming), a second client that drags and
disconnects mid-drag (the server runs on), the refusals of a request without
the token and of a foreign Origin, and the page's stop (exit 0, the summary
with the new K). Beside it, on programs of their own: the stress of
tools/cl/live_stress.py, the handouts' live sections, then the hostile
client's cases (tools/cl/live_hostile.py), then the tiny frames and the
reconnection storm (tools/cl/live_storm.py)."""
import json
import math
import os
import shutil
import signal
import subprocess
import threading
import time
import urllib.error
import urllib.request
from pathlib import Path

from .base import BIN, BUILD
from .live import read_url
from .live_handouts import check_handouts
from .live_hostile import IDLE_SOCKETS, PING_MIN_FPS, PING_RSS_BYTES, check_hostile
from .live_storm import MIN_FPS, STORM_RATE, STORM_RSS_BYTES, TINY_SOCKETS, check_storm
from .live_stress import FLOOD, check_stress
from .requirements import browser as find_browser

CHROMIUM_FLAGS = ["--headless", "--disable-gpu", "--no-sandbox", "--use-gl=angle", "--use-angle=swiftshader",
                  "--enable-unsafe-swiftshader", "--window-size=800,600", "--remote-debugging-port=0",
                  "--no-first-run", "--hide-scrollbars"]


class DevTools:
    """One page of Chromium over its DevTools WebSocket: commands and JavaScript."""

    def __init__(self, websocket_url):
        import websocket  # Debian's python3-websocket
        self.socket = websocket.create_connection(websocket_url, timeout=20, suppress_origin=True)
        self.next_id = 0

    def call(self, method, **params):
        self.next_id += 1
        self.socket.send(json.dumps({"id": self.next_id, "method": method, "params": params}))
        while True:
            reply = json.loads(self.socket.recv())
            if reply.get("id") == self.next_id:
                if "error" in reply:
                    raise RuntimeError(f"{method}: {reply['error']}")
                return reply.get("result", {})

    def js(self, expression):
        result = self.call("Runtime.evaluate", expression=expression, returnByValue=True)
        if "exceptionDetails" in result:
            raise RuntimeError(f"{expression[:60]}: {result['exceptionDetails'].get('text')}")
        return result["result"].get("value")

    def mouse(self, kind, x, y, modifiers=0):
        """A left-button mouse event at CSS px (x, y); modifiers 8: Shift held."""
        self.call("Input.dispatchMouseEvent", type=kind, x=x, y=y, button="left",
                  buttons=0 if kind == "mouseReleased" else 1, clickCount=1, modifiers=modifiers)

    def status(self):
        text = self.js("document.body.getAttribute('data-status')")
        return json.loads(text) if text else None

    def wait(self, what, test, seconds=8.0):
        """Poll test() (a value, or None/False) until it holds; raise naming `what`."""
        end, last = time.monotonic() + seconds, ""
        while time.monotonic() < end:
            try:
                value = test()
            except (RuntimeError, KeyError, TypeError) as error:  # the page still loading
                value, last = None, f" ({error})"
            if value:
                return value
            time.sleep(0.05)
        raise RuntimeError(f"waited {seconds:.0f} s for {what}{last}")

    def close(self):
        self.socket.close()


def start_chromium(chromium, url, profile):
    """Chromium on `url`; (process, DevTools of its page)."""
    process = subprocess.Popen([chromium, *CHROMIUM_FLAGS, f"--user-data-dir={profile}", url],
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    port_file = Path(profile) / "DevToolsActivePort"
    end = time.monotonic() + 20
    while not port_file.is_file() or not port_file.read_text(encoding="utf-8").strip():
        if time.monotonic() > end or process.poll() is not None:
            raise RuntimeError("Chromium did not open its DevTools port")
        time.sleep(0.05)
    port = port_file.read_text(encoding="utf-8").split()[0]
    while True:
        pages = json.loads(urllib.request.urlopen(f"http://127.0.0.1:{port}/json/list", timeout=5).read())
        pages = [p for p in pages if p.get("type") == "page" and p.get("url", "").startswith("http://127.0.0.1")]
        if pages:
            return process, DevTools(pages[0]["webSocketDebuggerUrl"])
        if time.monotonic() > end:
            raise RuntimeError("Chromium opened no page")
        time.sleep(0.05)


def refusal_problems(port, token):
    """A request for the page without the token, and a WebSocket from a foreign Origin: both refused."""
    import websocket
    problems = []
    try:
        urllib.request.urlopen(f"http://127.0.0.1:{port}/", timeout=5)
        problems.append("the page was served without the token")
    except urllib.error.HTTPError as error:
        if error.code != 403:
            problems.append(f"the page without the token: HTTP {error.code}, not 403")
    try:
        websocket.create_connection(f"ws://127.0.0.1:{port}/ws?token={token}", timeout=5,
                                    origin="http://evil.example").close()
        problems.append("a WebSocket from Origin http://evil.example was accepted")
    except websocket.WebSocketBadStatusException as error:
        if error.status_code != 403:
            problems.append(f"a WebSocket from a foreign Origin: HTTP {error.status_code}, not 403")
    except (websocket.WebSocketException, OSError) as error:
        problems.append(f"a WebSocket from a foreign Origin: {error}, not HTTP 403")
    return problems


def second_client(port, token, particle):
    """A client without a browser: it drags `particle`, sees itself hold it, and
    goes away mid-drag without a closing handshake. Returns what went wrong."""
    import websocket
    client = websocket.create_connection(f"ws://127.0.0.1:{port}/ws?token={token}", timeout=10)
    hello = json.loads(client.recv())
    if hello.get("type") != "hello":
        return [f"the second client's first message is {hello.get('type')!r}, not hello"]
    target = None
    end = time.monotonic() + 8
    while time.monotonic() < end:
        message = client.recv()
        if isinstance(message, bytes):
            n = hello["particles"]
            if target is None:
                import struct
                x = struct.unpack_from(f"<{3 * n}f", message)
                target = [x[3 * particle], x[3 * particle + 1] + 0.1, x[3 * particle + 2]]
                client.send(json.dumps({"cmd": "drag", "particle": particle, "x": target}))
            client.send('{"cmd": "ack"}')
            continue
        status = json.loads(message)
        if status.get("type") == "frame" and any(h["particle"] == particle for h in status["held"]):
            client.sock.close()  # gone mid-drag: no release, no closing handshake
            return []
    client.close()
    return [f"the second client never saw particle {particle} held"]


def pin_and_reset(page, particle, scene_pinned):
    """Shift-click pins `particle` (the simulation lists it pinned and it stays
    where it is while the run goes on); reset brings back the scene's first
    state (frame 0 again, its own pins only). Returns what went wrong."""
    problems = []
    page.js("document.getElementById('pause').click()")
    page.wait("the run paused", lambda: page.status()["paused"])
    at = page.js(f"CLLive.screenOf(CLLive.position({particle}))")
    page.mouse("mousePressed", *at, modifiers=8)
    page.mouse("mouseReleased", *at, modifiers=8)
    page.wait(f"particle {particle} pinned", lambda: particle in page.status()["pinned"])
    where, frame = page.js(f"CLLive.position({particle})"), page.status()["frame"]
    page.js("document.getElementById('pause').click()")
    page.wait("10 frames with the particle pinned", lambda: page.status()["frame"] >= frame + 10)
    if math.dist(page.js(f"CLLive.position({particle})"), where) > 1e-6:
        problems.append(f"pin: particle {particle} moved while pinned")
    frame = page.status()["frame"]
    page.js("document.getElementById('reset').click()")
    status = page.wait("the reset", lambda: page.status()["frame"] < frame and page.status())
    if sorted(status["pinned"]) != sorted(scene_pinned):
        problems.append(f"reset: pinned {status['pinned']}, not the scene's {scene_pinned}")
    return problems


def drive(page, process, port, token):
    """The checks on the page; a list of what went wrong."""
    problems = []
    page.wait("the first frame drawn", lambda: page.js("document.body.getAttribute('data-ready')") == "1")
    page.js("document.getElementById('pause').click()")
    page.wait("the run paused", lambda: (page.status() or {}).get("paused"))
    scene_pinned = page.status()["pinned"]
    n = page.js("CLLive.mesh().particles")
    x = page.js(f"Array.from({{length: {n}}}, function (_, p) {{ return CLLive.position(p); }})")
    particle = min(range(n), key=lambda p: x[p][0] + x[p][1])  # the bottom-left corner of a hanging curtain
    neighbour = min((p for p in range(n) if p != particle), key=lambda p: math.dist(x[p], x[particle]))
    rest = math.dist(x[neighbour], x[particle])
    right = page.js("CLLive.cameraRight()")
    target = [a + 0.2 * r for a, r in zip(x[particle], right)]
    start = page.js(f"CLLive.screenOf({json.dumps(x[particle])})")
    end = page.js(f"CLLive.screenOf({json.dumps(target)})")
    page.mouse("mousePressed", *start)
    for k in range(1, 11):
        page.mouse("mouseMoved", start[0] + (end[0] - start[0]) * k / 10, start[1] + (end[1] - start[1]) * k / 10)
    def held_at_target():
        held = [h["x"] for h in page.status()["held"] if h["particle"] == particle]
        return held and (math.dist(held[0], target) < 5e-3 or time.monotonic() > give_up) and held[0]

    give_up = time.monotonic() + 5  # then the check reports where the simulation holds it
    held = page.wait("the simulation to hold the dragged particle", held_at_target)
    moved, off = math.dist(held, x[particle]), math.dist(held, target)
    if off > 5e-3 or abs(moved - 0.2) > 5e-3:
        problems.append(f"drag: particle {particle} held at {held}, {moved:.4f} m from where it was (0.2 asked), "
                        f"{off:.4f} m from the target {target} (tolerance 5 mm: a pixel)")
    marked = page.js("document.body.getAttribute('data-held')")  # the ball the page draws on it
    if marked != str(particle):
        problems.append(f"drag: the page marks {marked!r} as held, not {particle}")
    page.js("document.getElementById('pause').click()")  # resume, still holding
    frame = page.status()["frame"]
    page.wait("30 frames with the particle held", lambda: page.status()["frame"] >= frame + 30)
    near = page.js(f"CLLive.position({neighbour})")
    if math.dist(near, held) > 1.5 * rest:
        problems.append(f"drag: neighbour {neighbour} is {math.dist(near, held):.4f} m from the held particle "
                        f"after 30 frames (rest {rest:.4f} m): the cloth did not follow")
    page.mouse("mouseReleased", *end)
    page.wait("the release", lambda: not page.status()["held"])
    page.wait("the held mark gone", lambda: page.js("document.body.getAttribute('data-held')") == "")
    problems += pin_and_reset(page, particle, scene_pinned)

    page.js("var k = document.getElementById('knob-K'); k.value = 3; k.dispatchEvent(new Event('change'));")
    page.wait("a frame stepped with K = 3", lambda: page.status()["step_knobs"]["K"] == 3)
    page.js("CLLive.send('{\"cmd\": \"pause\"')")
    error = page.wait("the error line", lambda: page.js("document.getElementById('error').textContent"))
    if "malformed JSON" not in error:
        problems.append(f"malformed message: the page's error line is {error!r}")
    frame = page.status()["frame"]
    page.wait("frames after the malformed message", lambda: page.status()["frame"] >= frame + 10)

    problems += second_client(port, token, neighbour)
    frame = page.status()["frame"]
    page.wait("frames after the second client left mid-drag, nothing held",
              lambda: page.status()["frame"] >= frame + 10 and not page.status()["held"])
    problems += refusal_problems(port, token)
    if process.poll() is not None:
        problems.append(f"the program exited ({process.returncode}) before the page's stop")
    page.js("document.getElementById('stop').click()")
    return problems


def check_live(checks):
    """lab 04's reference live on a 16² curtain, driven in headless Chromium."""
    program = BIN / "lab04_pbd_solution"
    chromium = find_browser()
    try:
        import websocket  # noqa: F401
    except ImportError:
        websocket = None
    if not chromium or websocket is None:
        print("skip  the live page in a browser: chromium or python3-websocket is not installed "
              "(./course installs both when run as root)")
        return
    scratch = BUILD / "test-live"
    shutil.rmtree(scratch, ignore_errors=True)
    scratch.mkdir(parents=True)
    summary = scratch / "summary.json"
    started = time.monotonic()
    # The stress test runs beside the browser's, on a program of its own: the two share the 20 s.
    stress = {}

    def beside():  # the stress, the handouts' live sections, the hostile cases (each on programs of their own)
        try:
            stress.update(zip(("problems", "numbers"), check_stress(program)))
        except Exception as error:  # noqa: BLE001 (a thread's error is a check's problem, not a lost traceback)
            stress["problems"] = [f"the stress test: {type(error).__name__}: {error}"]
        handouts_started = time.monotonic()
        try:
            stress["handouts"] = check_handouts()
        except Exception as error:  # noqa: BLE001
            stress["handouts"] = [f"the handouts' live checks: {type(error).__name__}: {error}"]
        stress["handouts_seconds"] = time.monotonic() - handouts_started
        hostile_started = time.monotonic()  # after the browser's check, mostly: its ping flood measures a rate
        try:
            stress["hostile"] = check_hostile(program, scratch)
        except Exception as error:  # noqa: BLE001
            stress["hostile"] = ([f"the hostile cases: {type(error).__name__}: {error}"], {})
        stress["hostile_seconds"] = time.monotonic() - hostile_started
        storm_started = time.monotonic()  # last: it keeps a core busy for its 17 s
        try:
            stress["storm"] = check_storm(program)
        except Exception as error:  # noqa: BLE001
            stress["storm"] = ([f"the storm: {type(error).__name__}: {error}"], {})
        stress["storm_seconds"] = time.monotonic() - storm_started

    stressing = threading.Thread(target=beside)
    stressing.start()
    process = subprocess.Popen([str(program), "--scene", "curtain-16", "--live", "--summary", str(summary)],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, encoding="utf-8", errors="replace")
    problems, browser, page = [], None, None
    profile = scratch / "chromium-profile"
    try:
        port, token = read_url(process, 20)
        browser, page = start_chromium(chromium, f"http://127.0.0.1:{port}/?token={token}", profile)
        problems += drive(page, process, port, token)
        code = process.wait(timeout=10)
        if code != 0:
            problems.append(f"after the page's stop the program exited {code}, not 0")
    except (RuntimeError, OSError, subprocess.TimeoutExpired, ValueError, KeyError, TypeError) as error:
        problems.append(f"{type(error).__name__}: {error}")
    finally:
        if page:
            page.close()
        if browser:
            os.killpg(browser.pid, signal.SIGKILL)  # Chromium and the helpers it started, its own group
            browser.wait()
        if process.poll() is None:
            process.kill()
            problems.append("the program was still running: killed")
        out, err = process.communicate()
    if summary.is_file():
        knobs = json.loads(summary.read_text(encoding="utf-8")).get("knobs", {})
        if knobs.get("K") != 3:
            problems.append(f"the summary's knobs are {knobs}, not K = 3")
    else:
        problems.append("no summary written on exit")
    if "live run ended" not in out:
        problems.append(f"stdout has no 'live run ended' line: {out.strip()[-200:]!r}")
    problems += [f"stderr: {line}" for line in err.splitlines()
                 if "malformed JSON" not in line and "refused" not in line]
    checks.record(not problems, f"live lab 04 on a 16² curtain in headless Chromium ({time.monotonic() - started:.0f} s): "
                  "a drag of 0.2 m held (and marked) and followed, a shift-click pin, reset, K turned in the page, a "
                  "malformed message refused while frames kept coming, a second client gone mid-drag, no token and a foreign Origin refused, stop: exit 0",
                  problems)
    stressing.join(timeout=120)
    numbers = stress.get("numbers", {})
    checks.record(not stressing.is_alive() and not stress.get("problems", ["the stress test did not finish"]),
                  "live under stress, beside it: 3 clients that ack and never read (dropped after "
                  f"{numbers.get('ackers_dropped_after')} s), a flood of "
                  f"{FLOOD} refused messages ({numbers.get('flood_answered')} answered), 50 sockets held and a 100 MB "
                  f"message, while an honest client got {numbers.get('honest_fps')} frames/s (median, at least 20) "
                  f"and {numbers.get('honest_answered')} answers; the page in {numbers.get('page_seconds', 0):.2f} s, "
                  f"a new WebSocket greeted in {numbers.get('hello_seconds', 0):.2f} s (at most 2); RSS "
                  f"+{numbers.get('rss_rise_mb', 0):.1f} MB for the 100 MB message (under 10); SIGTERM "
                  f"{numbers.get('sigterm_seconds', 0):.2f} s; {numbers.get('stderr_lines')} stderr lines",
                  stress.get("problems", ["the stress test did not finish within 60 s"]))
    checks.record("handouts" in stress and not stress["handouts"],
                  f"live: the handouts' \"Try it live\" numbers and effects (labs 04, 06, 14) on the reference, driven "
                  f"over the page's socket ({stress.get('handouts_seconds', 0):.0f} s)",
                  stress.get("handouts", ["the handouts' live checks did not finish"]))
    hostile_problems, numbers = stress.get("hostile", (["the hostile cases did not finish"], {}))

    def seconds(key):
        return "-" if numbers.get(key) is None else f"{numbers[key]:.2f} s"

    checks.record(
        "hostile" in stress and not hostile_problems,
        f"live against a hostile local client ({stress.get('hostile_seconds', 0):.0f} s): names cut inside a UTF-8 "
        f"character answered (not exit 1); a 60 kB head in one write 431, a foreign Host 403, none 400, two Origins "
        f"400, a NUL inside Origin, a folded header line and 'Host :' 400; close codes 999, 1005, 5000, a "
        f"1-byte close body and a reason not UTF-8 closed 1002; C1 and bidi controls in a name shown as '?'; {IDLE_SOCKETS} idle sockets, then the page and a hello within 2 s; a ping flood "
        f"reading 64 kB every 0.3 s: RSS +{numbers.get('ping_rss_rise_mb', 0):.1f} MB (at most "
        f"{PING_RSS_BYTES >> 20}), the honest page {numbers.get('ping_honest_fps')} frames/s (median, at least "
        f"{PING_MIN_FPS}); SIGINT and the page's stop during a 1e8-iteration step: exit 0 with the summary after "
        f"{seconds('SIGINT_seconds')} and {seconds('stop_seconds')} (at most 1 s)",
        hostile_problems)
    storm_problems, numbers = stress.get("storm", (["the storm did not finish"], {}))
    checks.record(
        "storm" in stress and not storm_problems,
        f"live under floods ({stress.get('storm_seconds', 0):.0f} s): beside {TINY_SOCKETS} tiny-frame sockets the "
        f"honest page got {numbers.get('tiny_fps')} frames/s; during {STORM_RATE} WebSocket opens a second "
        f"{numbers.get('storm_fps')}, in the second after {numbers.get('after_fps')} (at least {MIN_FPS} each); RSS "
        f"+{numbers.get('rss_rise_mb', 0):.1f} MB (at most {STORM_RSS_BYTES >> 20}); the page's stop during a storm: "
        f"{numbers.get('stop_seconds', 0):.2f} s (at most 1)",
        storm_problems)
