"""What every figure module shares: matplotlib's pyplot on the Agg backend (unless MPLBACKEND
chooses one) and the atomic PNG writer. matplotlib is imported only when a figure is drawn."""

import os
import tempfile


def pyplot():
    """matplotlib.pyplot, on the Agg backend unless $MPLBACKEND names another."""
    import matplotlib

    if not os.environ.get("MPLBACKEND"):
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save(fig, path):
    """Save `fig` at `path` atomically (a temporary file in the target folder, then rename),
    with the usual permissions (0666 less the umask); nothing is left behind on failure. The
    folder must exist. Returns `path`."""
    path = os.fspath(path)
    directory = os.path.dirname(os.path.abspath(path))
    suffix = os.path.splitext(path)[1] or ".png"
    fd, tmp = tempfile.mkstemp(prefix=".tmp-", suffix=suffix, dir=directory)
    os.close(fd)
    try:
        fig.savefig(tmp, dpi=fig.dpi)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp's 0600 → the usual permissions
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.remove(tmp)
        raise
    return path
