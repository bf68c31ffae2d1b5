"""Re-running a tool with Debian's /usr/bin/python3 when the interpreter it was started with has no
numpy (e.g. a pyenv python3 first on PATH). Standard library only: imported before numpy."""

import os
import sys

SYSTEM = "/usr/bin/python3"


def need_numpy(tool, packages="python3-numpy"):
    """Returns when numpy is importable; otherwise re-executes the same command line with
    SYSTEM (once: an environment variable marks the re-run), or exits with one line naming the
    Debian packages to install."""
    try:
        import numpy  # noqa: F401
        return
    except ImportError:
        pass
    if (os.path.exists(SYSTEM) and os.environ.get("WP_SYSTEM_PYTHON_REEXEC") != "1"
            and os.path.realpath(sys.executable) != os.path.realpath(SYSTEM)):
        os.environ["WP_SYSTEM_PYTHON_REEXEC"] = "1"
        main = sys.modules["__main__"]
        # A tool run as a module (python3 -m tools.studies.NAME) re-runs as one.
        if getattr(main, "__spec__", None) is not None:
            os.execv(SYSTEM, [SYSTEM, "-m", main.__spec__.name] + sys.argv[1:])
        os.execv(SYSTEM, [SYSTEM] + sys.argv)
    sys.exit("%s: error: numpy is not importable by %s; install Debian's %s"
             % (tool, sys.executable, packages))
