"""What a command needs, found by what the system can do (a program on PATH,
a header where the compilers look, a Python module), and the one line that
installs what is missing: apt on Debian and Ubuntu (as root it installs there
and then: the fresh-machine rule), Homebrew on macOS, MSYS2's pacman on
Windows (where WSL2 and the dev container are the documented ways).

It imports nothing of the package and nothing outside Python's standard
library: tools/course.py checks a command's needs before it runs it, and
tools/gradescope/setup.sh runs this file as a script
(`python3 tools/cl/requirements.py grade`). CL_SYSTEM (debian, darwin,
windows, linux) and CL_ROOT (0 or 1) pretend another system, for trying the
messages; ./course test checks them (checks.py, `message_problems` below).
"""
import importlib.util
import os
import re
import shutil
import subprocess
import sys
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent.parent
MSYS2 = "mingw-w64-x86_64-"  # MSYS2's MINGW64 packages
PIP = {"PIL": "pillow", "websocket": "websocket-client"}  # a module's pip name, where it differs
BROWSERS = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable")


@dataclass(frozen=True)
class Need:
    """One capability: `what` names it in the message; `kind` and `names` say
    how it is found (any one of the names); apt, brew and pacman what installs
    it there. An apt name `a|b` is the first of the two the system's apt
    knows (`a|` : a, or nothing where apt has no such package). An optional
    need never stops a command; on Debian as root it is installed with the
    others."""

    what: str
    kind: str  # program, cmake, header, module, openmp, fuzzer
    names: tuple
    apt: tuple = ()
    brew: tuple = ()
    pacman: tuple = ()
    optional: bool = False


CMAKE = Need("cmake >= 3.20", "cmake", ("cmake",), ("cmake",), ("cmake",), ("cmake",))
COMPILER = Need("a C++17 compiler", "program", ("c++", "g++", "clang++"), ("g++",), (), ("gcc",))
BUILDER = Need("ninja or make", "program", ("ninja", "make"), ("ninja-build",), ("ninja",), ("ninja",))
EIGEN = Need("Eigen 3.4", "header", ("eigen3/Eigen/Core",), ("libeigen3-dev",), ("eigen@3",), ("eigen3",))
JSON = Need("nlohmann-json", "header", ("nlohmann/json.hpp",), ("nlohmann-json3-dev",), ("nlohmann-json",),
            ("nlohmann-json",))
CLI11 = Need("CLI11", "header", ("CLI/CLI.hpp",), ("libcli11-dev",), ("cli11",), ("cli11",))
CATCH2 = Need("Catch2 2.13 or 3", "header", ("catch2/catch_test_macros.hpp", "catch2/catch.hpp"), ("catch2",),
              ("catch2",), ("catch",))
OPENMP = Need("OpenMP (libomp)", "openmp", (), (), ("libomp",), ())  # g++ brings its own (libgomp)
BOOST = Need("Boost headers", "header", ("boost/version.hpp",), ("libboost-dev",), ("boost",), ("boost",),
             optional=True)  # the live mode's
CHOLMOD = Need("CHOLMOD (SuiteSparse)", "header", ("suitesparse/cholmod.h", "cholmod.h"),
               ("libsuitesparse-dev", "libopenblas-dev"), ("suite-sparse",), ("suitesparse",), optional=True)
MATPLOTLIB = Need("Python's matplotlib", "module", ("matplotlib",), ("python3-matplotlib",), ("python-matplotlib",),
                  ("python-matplotlib",))
NUMPY = Need("numpy", "module", ("numpy",), ("python3-numpy",), ("numpy",), ("python-numpy",))
PIL = Need("Pillow", "module", ("PIL",), ("python3-pil",), ("pillow",), ("python-pillow",))
# The instructor's: the fuzzer (clang and its libFuzzer runtime), the browser
# checks (a Chromium, driven over its DevTools protocol), Google Benchmark,
# CHOLMOD as CI has it, ccache (never required by the build, always by CI's time).
CLANG = Need("clang++", "program", ("clang++",), ("clang",), ("llvm",), ("clang",))
FUZZER = Need("clang's libFuzzer runtime", "fuzzer", (), ("libclang-rt-dev|",), ("llvm",), ("compiler-rt",))
BROWSER = Need("Chromium (or Chrome)", "program", BROWSERS, ("chromium|chromium-browser",), (), ())
WEBSOCKET = Need("Python's websocket-client", "module", ("websocket",), ("python3-websocket",), (), ())
BENCHMARK = Need("Google Benchmark", "header", ("benchmark/benchmark.h",), ("libbenchmark-dev",),
                 ("google-benchmark",), ("benchmark",))
CHOLMOD_CI = Need(CHOLMOD.what, CHOLMOD.kind, CHOLMOD.names, CHOLMOD.apt, CHOLMOD.brew, CHOLMOD.pacman)
CCACHE = Need("ccache", "program", ("ccache",), ("ccache",), ("ccache",), ("ccache",))

BUILD = (CMAKE, COMPILER, BUILDER, EIGEN, JSON, CLI11, CATCH2, OPENMP, BOOST, CHOLMOD)
FIGURES = (MATPLOTLIB, NUMPY, PIL)
INSTRUCTOR = (CLANG, FUZZER, BROWSER, WEBSOCKET, BENCHMARK, CHOLMOD_CI, CCACHE)
# What each command checks before it runs; a command not listed needs nothing
# (help, view, release: Python alone).
COMMANDS = {
    "grade": BUILD, "run": BUILD, "live": BUILD, "handouts": BUILD, "claims": BUILD, "mistakes": BUILD,
    "autograder": BUILD, "extremes": BUILD + FIGURES, "demo": BUILD + FIGURES, "plots": FIGURES,
    "bench": BUILD + FIGURES + (BENCHMARK, CHOLMOD_CI), "fuzz": (CMAKE, BUILDER, CLANG, FUZZER),
    "sanitize": BUILD + (WEBSOCKET,), "test": BUILD + FIGURES + INSTRUCTOR,
}


@dataclass
class System:
    """Where to look, and how to install: `kind` is debian, darwin, windows or
    linux (another Linux, without apt). The defaults are this machine's;
    message_problems passes empty ones to see every message."""

    kind: str
    root: bool
    path: str = None  # PATH, for programs (None: this process's)
    prefixes: list = None  # folders with include/ (None: where this kind installs)
    modules: set = None  # Python modules there are (None: ask this Python)
    apt_known: object = None  # name -> whether apt has it (None: ask apt-cache)
    found: dict = field(default_factory=dict)

    def program(self, name):
        return shutil.which(name, path=self.path)

    def header(self, relative):
        prefixes = self.prefixes if self.prefixes is not None else default_prefixes(self.kind)
        for prefix in prefixes:
            path = Path(prefix) / "include" / relative
            if path.is_file():
                return path
        return None

    def module(self, name):
        if self.modules is not None:
            return name in self.modules
        return importlib.util.find_spec(name) is not None

    def has(self, need):
        if need not in self.found:
            self.found[need] = bool(probe(self, need))
        return self.found[need]


def this_system():
    """The System this process runs on (CL_SYSTEM, CL_ROOT pretend another)."""
    kind = os.environ.get("CL_SYSTEM")
    if not kind:
        if sys.platform == "darwin":
            kind = "darwin"
        elif os.name == "nt" or sys.platform in ("cygwin", "msys"):
            kind = "windows"
        elif shutil.which("dpkg-query") and shutil.which("apt-get"):
            kind = "debian"
        else:
            kind = "linux"
    root = os.environ.get("CL_ROOT")
    root = root == "1" if root in ("0", "1") else (hasattr(os, "geteuid") and os.geteuid() == 0)
    return System(kind, root)


def default_prefixes(kind):
    """The folders whose include/ the compilers and CMake search, for KIND."""
    found = [p for p in os.environ.get("CMAKE_PREFIX_PATH", "").split(os.pathsep) if p]
    if os.environ.get("CONDA_PREFIX"):
        conda = Path(os.environ["CONDA_PREFIX"])
        found += [str(conda), str(conda / "Library")]
    if kind == "darwin":
        brew = os.environ.get("HOMEBREW_PREFIX")
        found += [brew] if brew else []
        found += ["/opt/homebrew", "/usr/local", "/opt/local",
                  *(str(p) for p in homebrew_kegs())]
    elif kind == "windows":
        found += [sys.prefix, os.environ.get("MSYSTEM_PREFIX", ""), "C:/msys64/mingw64", "C:/msys64/ucrt64"]
        if os.environ.get("VCPKG_ROOT"):
            found.append(str(Path(os.environ["VCPKG_ROOT"]) / "installed" / "x64-windows"))
    else:
        found += ["/usr/local", "/usr"]
    return [p for p in found if p]


def homebrew_kegs():
    """Homebrew's keg-only formulae the build needs (not linked into its
    include/): eigen@3 (Homebrew's `eigen` is 5.x) and libomp."""
    kegs = []
    for prefix in (os.environ.get("HOMEBREW_PREFIX"), "/opt/homebrew", "/usr/local"):
        for name in ("eigen@3", "libomp"):
            keg = Path(prefix or "/nonexistent") / "opt" / name
            if keg.is_dir() and keg not in kegs:
                kegs.append(keg)
    return kegs


def cmake_hints(system=None):
    """CMake options that point it at what `requirements` found where CMake
    does not look by itself: macOS's Homebrew kegs (eigen@3, libomp)."""
    system = system or this_system()
    if system.kind != "darwin":
        return []
    kegs = homebrew_kegs()
    hints = [f"-DCMAKE_PREFIX_PATH={';'.join(str(k) for k in kegs)}"] if kegs else []
    libomp = [k for k in kegs if k.name == "libomp"]
    return hints + ([f"-DOpenMP_ROOT={libomp[0]}"] if libomp else [])


def version_of(text, major, minor):
    """(major, minor) from two #define lines of a header's text, or None."""
    found = [re.search(rf"#define\s+{name}\s+(\d+)", text) for name in (major, minor)]
    return tuple(int(m.group(1)) for m in found) if all(found) else None


def probe(system, need):
    """Whether `system` has `need` (see Need.kind)."""
    if need.kind == "program":
        return any(system.program(name) for name in need.names)
    if need.kind == "module":
        return all(system.module(name) for name in need.names)
    if need.kind == "cmake":
        program = system.program("cmake")
        if not program:
            return False
        said = subprocess.run([program, "--version"], capture_output=True, encoding="utf-8", errors="replace",
                              check=False).stdout
        match = re.search(r"version (\d+)\.(\d+)", said)
        return bool(match) and (int(match.group(1)), int(match.group(2))) >= (3, 20)
    if need.kind == "header":
        for name in need.names:
            path = system.header(name)
            if path is None:
                continue
            if need is EIGEN:  # 3.4, or 5.x (whose version is in Eigen/Version; its Macros.h keeps world 3)
                if (path.parent / "Version").is_file():
                    return True
                text = (path.parent / "src/Core/util/Macros.h").read_text(encoding="utf-8", errors="replace")
                return (version_of(text, "EIGEN_WORLD_VERSION", "EIGEN_MAJOR_VERSION") or (0, 0)) >= (3, 4)
            if name == "catch2/catch.hpp":  # Catch2 2.x: 2.13 at least
                text = path.read_text(encoding="utf-8", errors="replace")[:4000]
                return (version_of(text, "CATCH_VERSION_MAJOR", "CATCH_VERSION_MINOR") or (0, 0)) >= (2, 13)
            return True
        return False
    if need.kind == "openmp":  # Apple's clang has no OpenMP of its own: Homebrew's libomp
        return system.kind != "darwin" or system.header("omp.h") is not None or any(
            (keg / "include" / "omp.h").is_file() for keg in homebrew_kegs())
    if need.kind == "fuzzer":
        return fuzzer_runtime(system) is not None
    raise ValueError(need.kind)


def fuzzer_runtime(system):
    """clang's libFuzzer library (libclang_rt.fuzzer*.a in clang's resource
    folder), or None."""
    clang = system.program("clang++")
    if not clang:
        return None
    folder = subprocess.run([clang, "-print-resource-dir"], capture_output=True, encoding="utf-8",
                            errors="replace", check=False).stdout.strip()
    return next(iter(sorted(Path(folder).glob("lib/**/libclang_rt.fuzzer*.a"))), None) if folder else None


def browser(system=None):
    """A Chromium or Chrome on PATH (Debian's chromium, Ubuntu's
    chromium-browser snap wrapper, Google's chrome), or None."""
    system = system or this_system()
    return next((found for name in BROWSERS if (found := system.program(name))), None)


def missing(command, system):
    """(required, optional) needs of `command` that `system` lacks."""
    needs = list(dict.fromkeys(COMMANDS.get(command, ())))
    absent = [need for need in needs if not system.has(need)]
    return [n for n in absent if not n.optional], [n for n in absent if n.optional]


def apt_names(needs, system):
    """The apt packages of `needs`, each `a|b` resolved by what apt knows."""
    known = system.apt_known or apt_has
    names = []
    for need in needs:
        for name in need.apt:
            if "|" not in name:
                names.append(name)
                continue
            options = name.split("|")
            choice = next((option for option in options if option and known(option)), None)
            if choice is None and not options[-1]:
                continue  # `a|`: nothing to install where apt has no a (clang brings it)
            names.append(choice or options[0])
    return list(dict.fromkeys(names))


def apt_has(name):
    """Whether apt has a candidate for package NAME (apt-cache policy)."""
    try:
        said = subprocess.run(["apt-cache", "policy", name], capture_output=True, encoding="utf-8",
                              errors="replace", check=False).stdout
    except OSError:  # no apt here (CL_SYSTEM=debian pretends)
        return False
    match = re.search(r"Candidate:\s*(\S+)", said)
    return bool(match) and match.group(1) != "(none)"


def install_line(needs, system):
    """The one command that installs `needs` on `system`, as the user types it."""
    if system.kind == "debian":
        names = apt_names(needs, system)
        return ("" if system.root else "sudo ") + "apt-get install -y " + " ".join(names) if names else ""
    if system.kind == "darwin":
        names = list(dict.fromkeys(name for need in needs for name in need.brew))
        line = "brew install " + " ".join(names) if names else ""
        if COMPILER in needs:  # Apple's clang comes with the command line tools, not with Homebrew
            line = "xcode-select --install" + (f" && {line}" if line else "")
        return line
    if system.kind == "windows":
        names = list(dict.fromkeys(MSYS2 + name for need in needs for name in need.pacman))
        return "pacman -S --needed " + " ".join(names) if names else ""
    return ""


def message(command, needs, system):
    """The one line that says what `command` lacks and how to install it."""
    what = ", ".join(need.what for need in needs)
    line = install_line(needs, system)
    if system.kind == "windows":
        how = ("on Windows use WSL2 (Ubuntu 24.04) or the dev container (README), or, for the native "
               f"MinGW-w64 build, in MSYS2's MINGW64 shell: {line}" if line else
               "on Windows use WSL2 (Ubuntu 24.04) or the dev container (README)")
        modules = [PIP.get(name, name) for need in needs if need.kind == "module" for name in need.names]
        if modules:  # python.org's Python (the py launcher) takes them from pip, not from MSYS2
            how += f"; python.org's Python: py -3 -m pip install {' '.join(modules)}"
    elif system.kind == "linux":
        how = "install them with your system's package manager (Debian and Ubuntu: ./course installs them as root)"
    else:
        how = f"install them with: {line}"
    return f"course {command}: missing {what}; {how}"


def shown(path):
    return path.relative_to(ROOT) if path.is_relative_to(ROOT) else path


INSTALLED_STAMP = "packages-installed"  # in the build tree: when ./course last installed packages


def install(needs, system, log_path, recommends=True):
    """apt-get install the packages of `needs` (root on Debian); False when apt failed."""
    names = apt_names(needs, system)
    log_path.parent.mkdir(parents=True, exist_ok=True)
    print(f"course: installing {' '.join(names)} (log: {shown(log_path)})", flush=True)
    env = dict(os.environ, DEBIAN_FRONTEND="noninteractive")
    extra = [] if recommends else ["--no-install-recommends"]
    with open(log_path, "a", encoding="utf-8") as log:
        for step in (["apt-get", "update"], ["apt-get", "install", "-y", *extra, *names]):
            if subprocess.run(step, stdout=log, stderr=subprocess.STDOUT, env=env, check=False).returncode:
                return False
    return True


def ensure(command, system=None, log_path=None, recommends=True):
    """Check `command`'s needs; on Debian as root install what is missing.
    (exit code, line): (0, None) when all is there, else 2 (or 1: apt failed)
    and the one line to print on stderr."""
    system = system or this_system()
    required, optional = missing(command, system)
    if not required:
        return 0, None
    if system.kind == "debian" and system.root and system.apt_known is None:
        build_dir = ROOT / os.environ.get("CL_BUILD_DIR", "build")
        log_path = log_path or build_dir / "apt.log"
        if not install(required + optional, system, log_path, recommends):
            return 1, f"course {command}: apt-get failed, see {shown(log_path)}"
        # A tree configured before this install cached what it did not find
        # (Google Benchmark, Boost): the stamp makes the next build configure
        # again (build.configure), so nothing installed now stays unused.
        build_dir.mkdir(parents=True, exist_ok=True)
        (build_dir / INSTALLED_STAMP).touch()
        system.found.clear()
        importlib.invalidate_caches()  # python3-matplotlib and the like, just installed for this Python
        required, _ = missing(command, system)
        if not required:
            return 0, None
    return 2, message(command, required, system)


# ---------------------------------------------------------------- the check

EXPECTED = {  # what a system with nothing installed is told, per kind (./course grade)
    "darwin": "course grade: missing cmake >= 3.20, a C++17 compiler, ninja or make, Eigen 3.4, nlohmann-json, "
              "CLI11, Catch2 2.13 or 3, OpenMP (libomp); install them with: xcode-select --install && brew install "
              "cmake ninja eigen@3 nlohmann-json cli11 catch2 libomp",
    "windows": "course grade: missing cmake >= 3.20, a C++17 compiler, ninja or make, Eigen 3.4, nlohmann-json, "
               "CLI11, Catch2 2.13 or 3; on Windows use WSL2 (Ubuntu 24.04) or the dev container (README), or, "
               "for the native MinGW-w64 build, in MSYS2's MINGW64 shell: pacman -S --needed "
               "mingw-w64-x86_64-cmake mingw-w64-x86_64-gcc mingw-w64-x86_64-ninja mingw-w64-x86_64-eigen3 "
               "mingw-w64-x86_64-nlohmann-json mingw-w64-x86_64-cli11 mingw-w64-x86_64-catch",
    "debian": "course grade: missing cmake >= 3.20, a C++17 compiler, ninja or make, Eigen 3.4, nlohmann-json, "
              "CLI11, Catch2 2.13 or 3; install them with: sudo apt-get install -y cmake g++ ninja-build "
              "libeigen3-dev nlohmann-json3-dev libcli11-dev catch2",
}


def message_problems():
    """What is wrong with the messages of a system with nothing installed:
    macOS, Windows and Debian without root, told in one line each (EXPECTED),
    exit 2; Ubuntu's chromium-browser chosen where apt has no chromium; help
    and view need nothing. Empty when all is right."""
    problems = []
    for kind, expected in EXPECTED.items():
        empty = System(kind, root=False, path="", prefixes=[], modules=set(), apt_known=lambda name: True)
        code, line = ensure("grade", empty)
        if (code, line) != (2, expected):
            problems.append(f"{kind}: exit {code}, said {line!r}, not {expected!r}")
    ubuntu = System("debian", root=False, path="", prefixes=[], modules=set(),
                    apt_known=lambda name: name != "chromium" and name != "libclang-rt-dev")
    names = apt_names(missing("test", ubuntu)[0], ubuntu)
    if "chromium-browser" not in names or "libclang-rt-dev" in names:
        problems.append(f"Ubuntu (no chromium, no libclang-rt-dev in apt): {' '.join(names)}")
    for command in ("help", "view", "release"):
        if ensure(command, System("darwin", root=False, path="", prefixes=[], modules=set()))[0]:
            problems.append(f"./course {command} asks for something on a bare system")
    return problems


if __name__ == "__main__":  # tools/gradescope/setup.sh: python3 requirements.py COMMAND (as root: installs)
    exit_code, said = ensure(sys.argv[1] if len(sys.argv) > 1 else "grade", recommends=False)
    if said:
        print(said, file=sys.stderr)
    sys.exit(exit_code)
