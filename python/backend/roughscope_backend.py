"""PEP 517 build backend of roughscope: setuptools' own backend (setuptools.build_meta), made
reachable from an isolated build environment without PyPI.

pip and `python3 -m build` build in an isolated environment holding only the packages that
pyproject.toml's build-system.requires names, downloaded from PyPI. PyPI is not reachable where
roughscope is built, so requires is empty and this module, found through backend-path, hands the
work to the setuptools and wheel of the interpreter itself (Debian's python3-setuptools and
python3-wheel): when they are not importable here (isolation), their folder is asked of the
interpreter run with -I (which ignores the isolation's PYTHONPATH and keeps the system
site-packages) and appended to sys.path. Nothing else is changed: every hook is setuptools'.
"""
import subprocess
import sys


def _find_build_meta():
    try:
        from setuptools import build_meta  # noqa: F401  (not isolated, or setuptools installed)
        import wheel  # noqa: F401
        return build_meta
    except ImportError:
        pass
    interpreter = getattr(sys, "_base_executable", None) or sys.executable
    probe = ("import os, setuptools, wheel; "
             "print(os.path.dirname(os.path.dirname(setuptools.__file__))); "
             "print(os.path.dirname(os.path.dirname(wheel.__file__)))")
    result = subprocess.run([interpreter, "-I", "-c", probe], capture_output=True, text=True,
                            check=False)
    if result.returncode != 0:
        raise ImportError(
            f"roughscope's build needs setuptools and wheel for {interpreter}: install Debian's "
            "python3-setuptools and python3-wheel (scripts/install-deps does)")
    for folder in dict.fromkeys(result.stdout.split()):
        if folder not in sys.path:
            sys.path.append(folder)
    from setuptools import build_meta
    return build_meta


_build_meta = _find_build_meta()


# setuptools would ask the frontend to install "wheel" from PyPI: it is found above instead.
def get_requires_for_build_wheel(config_settings=None):
    return []


def get_requires_for_build_sdist(config_settings=None):
    return []


def get_requires_for_build_editable(config_settings=None):
    return []


prepare_metadata_for_build_wheel = _build_meta.prepare_metadata_for_build_wheel
build_wheel = _build_meta.build_wheel
build_sdist = _build_meta.build_sdist
if hasattr(_build_meta, "build_editable"):
    prepare_metadata_for_build_editable = _build_meta.prepare_metadata_for_build_editable
    build_editable = _build_meta.build_editable
