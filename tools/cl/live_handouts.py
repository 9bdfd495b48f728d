"""The handouts' "Try it live" sections, checked over the page's WebSocket
(docs/DESIGN.md §3, "The live mode"): every sentence there that names a
number or an effect is driven here as the page would drive it (knobs,
drags, pins, reset) on the reference, and the statuses and frames the
program sends are read. The run is paused and taken one step at a time
with the page's own "step" button, so every number is read at the frame
the handout names, however loaded the machine: a real-time run read by a
slow client saw later frames than it asked for (lab 04's K = 2 strain read
3.7 for "about 6", 2026-12). A part of ./course test's live check
(tools/cl/live_checks.py)."""
import json
import struct
import subprocess
import time

from .base import BIN
from .live import read_url


class Session:
    """A lab's reference live, paused, driven by one client that acknowledges every frame."""

    def __init__(self, lab, args):
        import websocket  # Debian's python3-websocket
        self.process = subprocess.Popen([str(BIN / f"{lab}_solution"), "--live", *args], stdout=subprocess.PIPE,
                                        stderr=subprocess.PIPE, encoding="utf-8", errors="replace")
        port, token = read_url(self.process, 20)
        self.client = websocket.create_connection(f"ws://127.0.0.1:{port}/ws?token={token}", timeout=20)
        self.hello = json.loads(self.client.recv())
        self.n = self.hello["particles"]
        self.status, self.x, self.errors = None, None, []
        # Paused, then back to frame 0: every reading below is a count of steps from the scene's start.
        self.send(cmd="pause")
        self.send(cmd="reset")
        self.until(lambda status, x: status["paused"] and status["frame"] == 0)

    def send(self, **command):
        self.client.send(json.dumps(command))

    def until(self, test, seconds=30, errors=None):
        """Frames (each acknowledged) until test(status, x) holds, or a line sent to this page names `errors`;
        the status. RuntimeError after `seconds`."""
        import websocket
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            self.client.settimeout(max(0.01, min(1.0, end - time.monotonic())))
            try:
                message = self.client.recv()
            except websocket.WebSocketTimeoutException:
                continue
            if isinstance(message, bytes):
                self.x = struct.unpack_from(f"<{3 * self.n}f", message)
                self.client.send('{"cmd": "ack"}')
                if self.status and test(self.status, self.x):
                    return self.status
                continue
            text = json.loads(message)
            if text.get("type") == "frame":
                self.status = text
            elif text.get("type") == "error":
                self.errors.append(text["text"])
                if errors and any(errors in line for line in self.errors):
                    return self.status
        last = self.status or {}
        raise RuntimeError(f"{self.hello['lab']}: waited {seconds} s (last frame {last.get('frame')}, problem "
                           f"{last.get('problem')!r}, errors {self.errors[-2:]})")

    def change(self, test, **command):
        """A command applied (the run is paused, so at once); the status that shows it."""
        self.send(**command)
        return self.until(test)

    def set(self, knob, value):
        return self.change(lambda status, x: status["knobs"][knob] == value, cmd="set", knob=knob, value=value)

    def steps(self, count, stop=lambda status: False):
        """`count` steps, one "step" at a time, each status read (or fewer, once stop(status)); the last status."""
        status = self.status
        for _ in range(count):
            frame = status["frame"]
            self.send(cmd="step")
            status = self.until(lambda status, x: status["frame"] > frame)
            if stop(status):
                break
        return status

    def position(self, p):
        return list(self.x[3 * p:3 * p + 3])

    def close(self):
        try:
            self.send(cmd="stop")
            self.process.wait(timeout=10)
        finally:
            self.client.close()
            if self.process.poll() is None:
                self.process.kill()
                self.process.wait()


def drag_path(session, particle, goal, frames):
    """The particle led to `goal` in a straight line, one target a step, as a hand would (the caller lets go)."""
    start = session.position(particle)
    for k in range(1, frames + 1):
        target = [a + (b - a) * k / frames for a, b in zip(start, goal)]
        session.change(lambda status, x: any(h["particle"] == particle and h["x"] == target for h in status["held"]),
                       cmd="drag", particle=particle, x=target)
        session.steps(1)


def lab04():
    """labs/lab04_pbd/README.md, "Try it live" (curtain-32)."""
    import math
    problems, s = [], Session("lab04_pbd", ["--scene", "curtain-32"])
    try:
        strain = {10: s.steps(120)["max_strain"]}  # "after 2 s at K = 10"
        for k in (50, 2):  # up first: from a sagging curtain, K = 50 lifts it fast enough to pass the energy check
            s.set("K", k)
            strain[k] = s.steps(180)["max_strain"]  # "within 3 s"
        if not 2.2 <= strain[10] <= 3.0 or not 4.8 <= strain[2] <= 7.2 or not strain[50] < 0.5:
            problems.append(f"lab 04: max strain {strain} (K: strain), not about 2.6 at K = 10, under 0.5 at K = 50 "
                            "and about 6 at K = 2 (±20 %)")
        s.set("K", 1)
        status = s.steps(120, stop=lambda status: status["problem"])
        s.send(cmd="step")  # a run a problem paused takes no step until a reset
        refused = s.until(lambda status, x: False, seconds=10, errors="reset it first")
        if "energy rose" not in status["problem"] or refused["frame"] != status["frame"]:
            problems.append("lab 04: at K = 1 the run did not pause with an energy rise within 2 s")
        s.set("K", 10)
        s.send(cmd="reset")  # "reset starts the scene again and the run goes on": paused again, reset again
        s.send(cmd="pause")
        s.change(lambda status, x: status["paused"] and status["frame"] == 0 and not status["problem"], cmd="reset")
        s.steps(60)
        bottom = min(range(s.n), key=lambda p: s.position(p)[0] + s.position(p)[1])
        goal = [s.position(bottom)[0] + 0.3, s.position(bottom)[1], s.position(bottom)[2]]
        drag_path(s, bottom, goal, 15)
        s.change(lambda status, x: not status["held"], cmd="release", particle=bottom)
        at = s.position(bottom)[0]
        s.steps(2)
        if not s.position(bottom)[0] > at:
            problems.append("lab 04: the corner dragged sideways (+x) did not go on in +x after its release")
        s.change(lambda status, x: bottom in status["pinned"], cmd="pin", particle=bottom)
        pinned_strain = s.steps(120)["max_strain"]
        s.set("dt", 0.05)
        coarse = s.steps(60)["max_strain"]
        if not coarse > 1.2 * pinned_strain or math.isnan(coarse):
            problems.append(f"lab 04: with a corner pinned, dt 0.05 s gave max strain {coarse:.3g}, not more than at "
                            f"1/60 s ({pinned_strain:.3g}) by 20 %")
    finally:
        s.close()
    return problems


def lab06():
    """labs/lab06_projective_dynamics/README.md, "Try it live" (pd-curtain-32)."""
    problems, s = [], Session("lab06_projective_dynamics", ["--scene", "pd-curtain-32"])
    try:
        soft = s.steps(120)["max_strain"]
        before = s.steps(1)["frame"]
        s.set("K", 12)  # K alone: A does not depend on it, nothing is rebuilt
        turned = s.steps(1)
        if turned["last_rebuilt_frame"] > before:
            problems.append(f"lab 06: turning K rebuilt {turned['last_rebuilt']!r} at frame "
                            f"{turned['last_rebuilt_frame']} (A does not depend on K)")
        s.set("K", 10)
        s.set("k", 1e6)
        first = s.steps(1)
        if first["last_rebuilt_frame"] <= turned["frame"] or "factored" not in first["last_rebuilt"]:
            problems.append(f"lab 06: the step after k = 1e6 does not say A was factored again "
                            f"(last rebuilt {first['last_rebuilt']!r} at frame {first['last_rebuilt_frame']})")
        stiff = s.steps(120)["max_strain"]
        s.set("K", 100)
        converged = s.steps(120)["max_strain"]
        if not stiff > 0.1 * soft or not converged < 0.5 * stiff:
            problems.append(f"lab 06: max strain {soft:.3g} (k 1e4), {stiff:.3g} (k 1e6: not 100 times less, expected "
                            f"more than a tenth), {converged:.3g} (K 100: under half of K 10's expected)")
    finally:
        s.close()
    return problems


def lab14():
    """labs/lab14_contact/README.md, "Try it live" (drape-sphere, PBD)."""
    import math
    problems, s = [], Session("lab14_contact", ["--scene", "drape-sphere"])
    try:
        x0 = [s.position(p) for p in range(s.n)]
        middle = [sum(p[a] for p in x0) / s.n for a in range(3)]
        centre = min(range(s.n), key=lambda p: math.hypot(x0[p][0] - middle[0], x0[p][2] - middle[2]))
        status = s.steps(120)
        if abs(s.position(centre)[1] + 0.051) > 1e-3 or abs(status["max_strain"] - 0.4757) > 2e-3:
            problems.append(f"lab 14: at 2 s the centre is at y = {s.position(centre)[1]:.4f} m (−0.051 ± 0.001) and the "
                            f"max strain {status['max_strain']:.4f} (0.4757 ± 0.002)")
        corner = min(range(s.n), key=lambda p: x0[p][0] + x0[p][2])
        before = s.position(centre)
        drag_path(s, corner, [0, 0.2, 0.5], 30)
        moved = math.dist(s.position(centre), before)
        s.steps(60)
        held = math.dist(s.position(centre), before)
        if not moved < 0.02 or not moved + 0.005 < held < 0.2:
            problems.append(f"lab 14: the corner led to (0, 0.2, 0.5) in 0.5 s moved the centre {moved:.3f} m (under "
                            f"0.02) and, held there 1 s more, {held:.3f} m (more, by 5 mm at least, and under 0.2)")
        s.change(lambda status, x: not status["held"], cmd="release", particle=corner)
        s.steps(60)
        if not s.position(corner)[1] < 0.0:
            problems.append(f"lab 14: the corner let go at y = 0.2 m is at y = {s.position(corner)[1]:.3f} m 1 s later")
        s.change(lambda status, x: status["frame"] == 0, cmd="reset")
        s.set("mu", 0)
        s.steps(120)
        on_floor = s.position(centre)
        s.steps(60)
        glide = math.dist(s.position(centre), on_floor)
        if abs(on_floor[1] + 0.6) > 0.01 or not 0.3 <= glide <= 0.8:
            problems.append(f"lab 14: with mu = 0 the centre is at y = {on_floor[1]:.3f} m after 2 s (−0.6 ± 0.01) and "
                            f"glides {glide:.2f} m in the next second (0.3 to 0.8)")
    finally:
        s.close()
    return problems


def check_handouts():
    """Every live section's numbers and effects; a list of what went wrong. A student release of an
    early week has no later lab's reference: its sections wait for that week."""
    import websocket  # Debian's python3-websocket
    from .release import is_release
    problems = []
    checks = {"lab04_pbd": lab04, "lab06_projective_dynamics": lab06, "lab14_contact": lab14}
    for lab, check in checks.items():
        if is_release() and not (BIN / f"{lab}_solution").is_file():
            continue
        try:
            problems += check()
        except (RuntimeError, OSError, subprocess.TimeoutExpired, ValueError, KeyError, websocket.WebSocketException) as error:
            problems.append(f"{check.__name__}: {type(error).__name__}: {error}")
    return problems
