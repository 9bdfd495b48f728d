"""./course live labNN [--port N] [lab flags]: the lab's own executable (or
labNN_solution, the reference) stepping its scene live beside a page in the
browser (docs/DESIGN.md §3, "The live mode"). Builds the lab if needed, then
becomes the program (`--live [PORT]`): it prints the page's URL and runs
until Ctrl-C, SIGTERM or the page's stop. Without --port, CL_LIVE_PORT names
the port (the dev container sets it: one port VS Code forwards for every run).

`--bench` instead runs it in the background and measures, as a page would
see it (a WebSocket client that acknowledges every frame): the latency from
a drag message to the first frame that shows the particle held there (the
median of 50 drags), and the frames per second at speed 16 (as fast as the
steps go)."""
import json
import os
import re
import statistics
import subprocess
import sys
import time

from . import grade
from .base import ROOT, CourseError, become
from .build import BuildFailure, build_targets, configure
from .labs import executable, lab_dirs, resolve_lab

USAGE = "usage: ./course live labNN [--port N | --bench] [lab flags]  (labNN_solution: the reference)"


def live_command(argv):
    """(target name, argv of the program) for ./course live ARGV."""
    if not argv or argv[0].startswith("-"):
        raise CourseError(USAGE, code=2)
    token, rest = argv[0], list(argv[1:])
    solution = token.endswith("_solution")
    lab = resolve_lab(token.removesuffix("_solution"))
    port = []
    for at, word in enumerate(rest):
        if word == "--port" or word.startswith("--port="):
            value = word[len("--port="):] if "=" in word else (rest[at + 1] if at + 1 < len(rest) else "")
            if not value.isdigit() or not 1 <= int(value) <= 65535:
                raise CourseError(f"live: --port needs a number in [1, 65535], not {value!r}", code=2)
            port = [value]
            del rest[at:at + (1 if "=" in word else 2)]
            break
    if not port and os.environ.get("CL_LIVE_PORT"):  # the dev container's forwarded port
        value = os.environ["CL_LIVE_PORT"]
        if not value.isdigit() or not 1 <= int(value) <= 65535:
            raise CourseError(f"live: CL_LIVE_PORT needs a number in [1, 65535], not {value!r}", code=2)
        port = [value]
    if not has_live_mode(lab):
        live_labs = ", ".join(grade.lab_id(other) for other in lab_dirs() if has_live_mode(other))
        raise CourseError(f"live: {grade.lab_id(lab)} does not step in time, so it has no live mode "
                          f"(the labs that do: {live_labs})", code=2)
    name = lab + ("_solution" if solution else "")
    return name, [name, "--live", *port, *rest]


def has_live_mode(lab):
    """Whether the lab's program takes --live: its driver adds common/live.h's
    flag (the time-stepping labs do; the sweep labs 01-03 do not)."""
    main = ROOT / "labs" / lab / "main.cpp"
    return main.is_file() and "add_live_option(" in main.read_text(encoding="utf-8")


def read_url(process, seconds):
    """(port, token) from the live program's first line, waiting at most `seconds`: a program that
    hangs before it, ends, or prints something else raises RuntimeError (one line)."""
    import threading
    lines = []
    reader = threading.Thread(target=lambda: lines.append(process.stdout.readline()), daemon=True)
    reader.start()
    reader.join(seconds)
    if not lines:
        raise RuntimeError(f"the program printed no URL within {seconds:.0f} s")
    match = re.fullmatch(r"http://127\.0\.0\.1:(\d+)/\?token=([0-9a-f]{32})", lines[0].strip())
    if not match:
        said = lines[0].strip()
        if not said:
            try:
                said = f"nothing (exit {process.wait(timeout=5)})"
            except subprocess.TimeoutExpired:
                said = "nothing"
        raise RuntimeError(f"the program's first line is {said[:200]!r}, not its URL")
    return match.groups()


def bench(program, args):
    """Latency (s, median of 50 drags) and frames per second of `program --live ARGS`."""
    import websocket  # Debian's python3-websocket
    import tempfile
    errors = tempfile.TemporaryFile(mode="w+", encoding="utf-8")
    process = subprocess.Popen([str(program), *args], stdout=subprocess.PIPE, stderr=errors,
                               encoding="utf-8", errors="replace")
    try:
        try:
            port, token = read_url(process, 30)
        except RuntimeError as error:
            errors.seek(0)
            said = [line for line in errors.read().splitlines() if line.strip()]
            raise CourseError(f"live --bench: {said[-1] if said else error}", code=2) from None
        client = websocket.create_connection(f"ws://127.0.0.1:{port}/ws?token={token}", timeout=10)
        hello = json.loads(client.recv())
        n = hello["particles"]

        def next_status():
            while True:
                message = client.recv()
                if isinstance(message, bytes):
                    client.send('{"cmd": "ack"}')
                elif json.loads(message)["type"] == "frame":
                    return json.loads(message)

        client.send('{"cmd": "speed", "value": 16}')
        next_status()
        first, start = next_status()["frame"], time.monotonic()
        frames = 0
        while time.monotonic() - start < 3:
            last = next_status()
            frames += 1
        rate, steps = frames / (time.monotonic() - start), (last["frame"] - first) / (time.monotonic() - start)
        client.send('{"cmd": "speed", "value": 1}')
        pinned = set(next_status()["pinned"])
        particle = max(p for p in range(n) if p not in pinned)  # the last free particle
        latencies = []
        for k in range(50):
            target = [0.01 * (k % 5), -0.5 - 0.01 * k, 0.05]
            sent = time.monotonic()
            client.send(json.dumps({"cmd": "drag", "particle": particle, "x": target}))
            while True:
                held = next_status()["held"]
                if held and max(abs(a - b) for a, b in zip(held[0]["x"], target)) < 1e-9:
                    latencies.append(time.monotonic() - sent)
                    break
        client.send(json.dumps({"cmd": "release", "particle": particle}))
        client.send('{"cmd": "stop"}')
        process.wait(timeout=10)
        return statistics.median(latencies), rate, steps, n
    except (OSError, websocket.WebSocketException, subprocess.TimeoutExpired, ValueError, KeyError) as error:
        raise CourseError(f"live --bench: {type(error).__name__}: {error}", code=2) from None
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()
        errors.close()


def cmd_live(argv):
    measuring = "--bench" in argv
    name, args = live_command([a for a in argv if a != "--bench"])
    configure(log=sys.stderr)
    try:
        build_targets([name], log=sys.stderr)
    except BuildFailure as failure:
        raise CourseError(f"{name} does not build", details=failure.lines) from None
    program = executable(name)
    if measuring:
        latency, rate, steps, n = bench(program, args[1:])
        print(f"{name} {' '.join(args[2:])}: {n} particles; drag to frame {1e3 * latency:.2f} ms (median of 50); "
              f"{rate:.0f} frames/s received, {steps:.0f} steps/s at speed 16")
        return 0
    return become(program, [str(program), *args[1:]])
