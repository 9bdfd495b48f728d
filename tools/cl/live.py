"""./course live labNN [--port N] [lab flags]: the lab's own executable (or
labNN_solution, the reference) stepping its scene live beside a page in the
browser (docs/DESIGN.md §3, "The live mode"). Builds the lab if needed, then
becomes the program (`--live [PORT]`): it prints the page's URL and runs
until Ctrl-C, SIGTERM or the page's stop."""
import os
import sys

from .base import CourseError
from .build import BuildFailure, build_targets, configure
from .labs import executable, resolve_lab

USAGE = "usage: ./course live labNN [--port N] [lab flags]  (labNN_solution: the reference)"


def live_command(argv):
    """(target name, argv of the program) for ./course live ARGV."""
    if not argv or argv[0].startswith("-"):
        raise CourseError(USAGE, code=2)
    token, rest = argv[0], list(argv[1:])
    solution = token.endswith("_solution")
    lab = resolve_lab(token.removesuffix("_solution"))
    port = []
    if "--port" in rest:
        at = rest.index("--port")
        if at + 1 >= len(rest):
            raise CourseError("live: --port needs a number (1 … 65535)", code=2)
        port = [rest[at + 1]]
        del rest[at:at + 2]
    name = lab + ("_solution" if solution else "")
    return name, [name, "--live", *port, *rest]


def cmd_live(argv):
    name, args = live_command(argv)
    configure(log=sys.stderr)
    try:
        build_targets([name], log=sys.stderr)
    except BuildFailure as failure:
        raise CourseError(f"{name} does not build", details=failure.lines) from None
    program = executable(name)
    sys.stdout.flush()
    os.execv(str(program), [str(program), *args[1:]])
