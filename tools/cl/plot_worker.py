"""A plot-script runner that imports matplotlib and numpy once (./course plots
starts two, tools/cl/plots.py): each script then runs in a child forked from
it, as `python3 plots/NAME.py DIR` would run it — its own process, __main__,
its folder first on sys.path, its exit code and output — without paying the
imports again (about 1 s of CPU a script, 36 s over the course's figures).

Where there is no fork (Windows), or CL_PLOTS_SPAWN=1, each script instead
runs as `python SCRIPT DIR` in a process of its own, paying the imports: the
same result, slower.

Protocol, one JSON object per line: a job {"script", "args", "env"} on stdin,
its result {"code", "stdout", "stderr"} on stdout. Not a command of its own.
"""
import json
import os
import runpy
import subprocess
import sys
import tempfile
import traceback

FORK = hasattr(os, "fork") and os.environ.get("CL_PLOTS_SPAWN") != "1"


def run_child(job):
    """In the forked child: run the job's script as __main__; never returns."""
    code = 0
    try:
        os.environ.update(job["env"])
        script = job["script"]
        sys.argv = [script, *job["args"]]
        sys.path[0] = os.path.dirname(os.path.abspath(script))
        runpy.run_path(script, run_name="__main__")
    except SystemExit as exit_:
        if isinstance(exit_.code, str):
            print(exit_.code, file=sys.stderr)
            code = 1
        else:
            code = exit_.code or 0
    except BaseException as error:  # what `python3 SCRIPT` would print (from the script's frame on)
        frames = error.__traceback__
        while frames is not None and frames.tb_frame.f_code.co_filename != job["script"]:
            frames = frames.tb_next
        traceback.print_exception(type(error), error, frames or error.__traceback__)
        code = 1
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(code)


def spawn_job(job):
    """Run the job as `python SCRIPT ARGS` (no fork here); its result."""
    env = dict(os.environ, **job["env"], PYTHONIOENCODING="utf-8")  # its prints as the fork's would be
    done = subprocess.run([sys.executable, job["script"], *job["args"]], env=env,
                          capture_output=True, encoding="utf-8", errors="replace", check=False)
    return {"code": done.returncode, "stdout": done.stdout, "stderr": done.stderr}


def run_job(job):
    """Fork, run the job in the child with its output in temporary files; its result."""
    if not FORK:
        return spawn_job(job)
    with tempfile.TemporaryFile() as out, tempfile.TemporaryFile() as err:
        sys.stdout.flush()
        sys.stderr.flush()
        pid = os.fork()
        if pid == 0:
            os.dup2(out.fileno(), 1)
            os.dup2(err.fileno(), 2)
            run_child(job)
        _, status = os.waitpid(pid, 0)
        out.seek(0)
        err.seek(0)
        return {"code": os.waitstatus_to_exitcode(status),
                "stdout": out.read().decode(errors="replace"), "stderr": err.read().decode(errors="replace")}


def main():
    os.environ.setdefault("MPLBACKEND", "Agg")
    if FORK:
        import matplotlib  # noqa: F401 (imported here once, for every child)
        import matplotlib.pyplot  # noqa: F401
        import numpy  # noqa: F401
    for line in sys.stdin:  # a script's own prints go to its child's files, never here
        if line.strip():
            print(json.dumps(run_job(json.loads(line))), flush=True)


if __name__ == "__main__":
    main()
