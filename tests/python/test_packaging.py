"""Installing roughscope like any tool: the wheel (python3 -m build) in a fresh virtual
environment, the Debian packages (cpack -G DEB) unpacked into a scratch root, and one version
everywhere (CMakeLists.txt's project(), the CLI, roughscope.__version__, the CMake package, the
wheel, the .deb).

The wheel is built from a copy of the tracked sources (what a clone holds), by the standard
frontend in its default isolated mode, so the in-tree backend (python/backend) must find
Debian's setuptools without PyPI. Its CMake folder sits one level below the copy, as `build/` sits
below the clone, so ccache (CCACHE_BASEDIR) serves the objects `make build` compiled.
The .deb test runs cpack on the build folder of this test run ($ROUGHSCOPE_BUILD_DIR, set by ctest).
"""
import json
import os
import pathlib
import re
import shutil
import subprocess
import sys
import zipfile

import pytest

import roughscope as rs

from conftest import project_version

REPO = pathlib.Path(__file__).resolve().parents[2]
DEBIAN_PYTHON = "/usr/bin/python3"



def sh(args, **kwargs):
    proc = subprocess.run([str(a) for a in args], capture_output=True, text=True, **kwargs)
    assert proc.returncode == 0, f"{args[:3]}: exit {proc.returncode}\n{proc.stdout[-3000:]}\n" \
                                 f"{proc.stderr[-3000:]}"
    return proc.stdout


def build_dir():
    path = os.environ.get("ROUGHSCOPE_BUILD_DIR")
    if not path:
        pytest.skip("ROUGHSCOPE_BUILD_DIR not set (ctest sets it to the CMake build folder)")
    return pathlib.Path(path)


def tracked_copy(dest):
    """The files a clone holds: `git ls-files` (else the tree without build folders)."""
    try:
        files = subprocess.run(["git", "-C", str(REPO), "ls-files", "-z"], capture_output=True,
                               check=True).stdout.decode().split("\0")
    except (OSError, subprocess.CalledProcessError):
        shutil.copytree(REPO, dest, ignore=shutil.ignore_patterns("build*", "out", ".git"))
        return dest
    for rel in filter(None, files):
        src = REPO / rel
        if src.is_file():
            (dest / rel).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(src, dest / rel)
    return dest


# ---- one evaluation and one estimate, run by an installed package ------------------------------

SMOKE = """
import json
import numpy as np
import roughscope as rs
b = rs.very_rough_brightness(np.array([30.0, 45.5]), np.array([0.0, 0.0]), np.array([0.0, 0.0]),
                             0.3)
ratio = float(b[0] / b[1])
print(json.dumps({"version": rs.__version__, "file": rs.__file__,
                  "brightness": [float(x) for x in b], "ratio": ratio}))
"""


def smoke(python, env, cwd):
    return json.loads(sh([python, "-c", SMOKE], env=env, cwd=cwd).strip().splitlines()[-1])


def expected_smoke():
    import numpy as np

    b = rs.very_rough_brightness(np.array([30.0, 45.5]), np.array([0.0, 0.0]),
                                 np.array([0.0, 0.0]), 0.3)
    return [float(x) for x in b]


def test_wheel_builds_and_installs_into_a_fresh_venv(tmp_path):
    version = project_version()
    src = tracked_copy(tmp_path / "src")
    env = dict(os.environ)
    env.pop("PYTHONPATH", None)
    env["CCACHE_BASEDIR"] = str(src)
    env["ROUGHSCOPE_CMAKE_BUILD_DIR"] = str(src / "build-wheel")
    env.setdefault("CMAKE_BUILD_PARALLEL_LEVEL", "2")
    sh([DEBIAN_PYTHON, "-m", "build", "--wheel", "--outdir", tmp_path / "dist", src], env=env,
       cwd=tmp_path, timeout=1800)
    wheels = list((tmp_path / "dist").glob("*.whl"))
    assert len(wheels) == 1 and wheels[0].name.startswith(f"roughscope-{version}-"), wheels
    with zipfile.ZipFile(wheels[0]) as z:
        names = z.namelist()
        metadata = z.read(f"roughscope-{version}.dist-info/METADATA").decode()
    assert any(re.fullmatch(r"roughscope/_core\..*\.so", n) for n in names), names
    assert "roughscope/__init__.py" in names and "roughscope/report.py" in names
    assert f"\nVersion: {version}\n" in metadata and "Requires-Dist: numpy" in metadata
    # Nothing of the build tree in the clone's own `build/` or the sources' folders.
    assert not (src / "python" / "roughscope.egg-info").exists()

    venv = tmp_path / "venv"
    sh([DEBIAN_PYTHON, "-m", "venv", "--system-site-packages", venv], timeout=300)
    python = venv / "bin" / "python"
    sh([python, "-m", "pip", "install", "--no-index", "--no-cache-dir", wheels[0]], env=env,
       timeout=600)
    outside = tmp_path / "elsewhere"
    outside.mkdir()
    got = smoke(python, env, outside)
    assert got["version"] == version == rs.__version__
    assert pathlib.Path(got["file"]).is_relative_to(venv), got["file"]
    assert got["brightness"] == pytest.approx(expected_smoke(), rel=1e-14)
    # An estimate through the installed package: Eq. 17 inverts the brightness ratio it made.
    code = ("import roughscope as rs, json; "
            f"print(json.dumps(rs.estimate_slope({got['ratio']!r}, 30.0, 45.5)))")
    doc = json.loads(sh([python, "-c", code], env=env, cwd=outside).strip().splitlines()[-1])
    values = [v for k, v in doc.items() if "sigma_over_T" in k and isinstance(v, float)]
    assert values and min(abs(v - 0.3) for v in values) < 1e-6, doc


# ---- cmake --install with the Python package ------------------------------------------------

def test_cmake_install_puts_the_python_package_in_the_prefix_site_packages(tmp_path):
    build = build_dir()
    prefix = tmp_path / "prefix"
    # ROUGHSCOPE_INSTALL_PYTHON=ON given to the install script (the build was configured OFF).
    sh(["cmake", "-DROUGHSCOPE_INSTALL_PYTHON=ON", f"-DCMAKE_INSTALL_PREFIX={prefix}",
        "-DCMAKE_INSTALL_COMPONENT=runtime", "-P", build / "cmake_install.cmake"], timeout=600)
    pyver = f"{sys.version_info.major}.{sys.version_info.minor}"
    site = prefix / "lib" / f"python{pyver}" / "site-packages"
    assert list((site / "roughscope").glob("_core*.so")), sorted(prefix.rglob("*"))[:20]
    assert (prefix / "bin" / "roughscope").is_file()
    assert (prefix / "share" / "man" / "man1" / "roughscope.1.gz").is_file()
    # Without the option the same install leaves the package out.
    bare = tmp_path / "bare"
    sh(["cmake", f"-DCMAKE_INSTALL_PREFIX={bare}", "-DCMAKE_INSTALL_COMPONENT=runtime", "-P",
        build / "cmake_install.cmake"], timeout=600)
    assert (bare / "bin" / "roughscope").is_file() and not list(bare.rglob("_core*.so"))
    env = dict(os.environ, PYTHONPATH=str(site))
    got = smoke(DEBIAN_PYTHON, env, tmp_path)
    assert got["version"] == project_version()
    assert pathlib.Path(got["file"]).is_relative_to(site), got["file"]


# ---- the Debian packages -----------------------------------------------------------------------

def deb_field(deb, field):
    return sh(["dpkg-deb", "-f", deb, field]).strip()


@pytest.fixture(scope="module")
def debs(tmp_path_factory):
    build = build_dir()
    out = tmp_path_factory.mktemp("debs")
    sh(["cpack", "--config", build / "CPackConfig.cmake", "-G", "DEB", "-B", out], cwd=build,
       timeout=1200)
    found = {p.name.split("_")[0]: p for p in out.glob("*.deb")}
    assert set(found) == {"roughscope", "libroughscope-dev"}, found
    root = out / "root"
    for deb in found.values():
        sh(["dpkg-deb", "-x", deb, root])
    return found, root


def test_deb_fields(debs):
    found, _ = debs
    version = project_version()
    for deb in found.values():
        assert deb_field(deb, "Version") == version
        assert deb.name.endswith(f"_{version}_{sh(['dpkg', '--print-architecture']).strip()}.deb")
    depends = deb_field(found["roughscope"], "Depends")
    for package in ("python3-numpy", "libc6", "libstdc++6", "libopencv-core", "libraw", "libtiff"):
        assert package in depends, depends
    dev = deb_field(found["libroughscope-dev"], "Depends")
    assert f"roughscope (= {version})" in dev and "libceres-dev" in dev and "libeigen3-dev" in dev


def test_deb_cli_runs_from_a_scratch_root(debs, tmp_path):
    _, root = debs
    cli = root / "usr" / "bin" / "roughscope"
    assert sh([cli, "--version"]).strip() == f"roughscope {project_version()}"
    # A short measurement: the capture file of the installed documentation.
    example = root / "usr" / "share" / "doc" / "roughscope" / "docs" / "examples" / "measure"
    doc = sh([cli, "measure", example / "capture-file.json", "--json"], cwd=tmp_path)
    reference = sh([os.environ.get("ROUGHSCOPE_CLI") or REPO / "build" / "bin" / "roughscope",
                    "measure", REPO / "docs" / "examples" / "measure" / "capture-file.json",
                    "--json"], cwd=tmp_path)
    assert json.loads(doc)["roughscope_version"] == project_version()
    assert json.loads(doc)["sigma_over_T_gaussian"] is not None
    # The same numbers as the build tree's CLI (paths of the example files aside).
    assert doc.replace(str(example), "EXAMPLE") == reference.replace(
        str(REPO / "docs" / "examples" / "measure"), "EXAMPLE")


def test_deb_python_package_imports_from_the_root(debs, tmp_path):
    _, root = debs
    site = root / "usr" / "lib" / "python3" / "dist-packages"
    env = dict(os.environ, PYTHONPATH=str(site))
    got = smoke(DEBIAN_PYTHON, env, tmp_path)
    assert got["version"] == project_version()
    assert pathlib.Path(got["file"]).is_relative_to(site), got["file"]
    assert got["brightness"] == pytest.approx(expected_smoke(), rel=1e-14)


def test_deb_man_page_and_completion(debs, tmp_path):
    _, root = debs
    man_dir = root / "usr" / "share" / "man"
    env = dict(os.environ, MANPATH=str(man_dir), MANWIDTH="100")
    for page in ("roughscope", "roughscope-measure", "roughscope-model"):
        found = pathlib.Path(sh(["man", "-w", page], env=env).strip())
        assert found.is_relative_to(man_dir), found
    text = sh(["man", "-P", "cat", "roughscope"], env=env)
    assert "measure" in text and "roughscope-measure(1)" in re.sub(r".\x08", "", text)
    assert project_version() in text
    measure = re.sub(r".\x08", "", sh(["man", "-P", "cat", "roughscope-measure"], env=env))
    assert "--maps" in measure and "capture" in measure
    completion = root / "usr" / "share" / "bash-completion" / "completions" / "roughscope"
    program = (f"source '{completion}'; COMP_WORDS=(roughscope mea); COMP_CWORD=1; "
               "_roughscope; echo \"${COMPREPLY[@]}\"")
    assert sh(["bash", "--norc", "-c", program]).strip() == "measure"


def test_deb_cmake_package_version(debs):
    _, root = debs
    config = root / "usr" / "lib" / "cmake" / "roughscope" / "roughscopeConfigVersion.cmake"
    if not config.exists():
        config = next(root.glob("usr/lib/*/cmake/roughscope/roughscopeConfigVersion.cmake"))
    assert f'set(PACKAGE_VERSION "{project_version()}")' in config.read_text()
    archives = list(root.glob("usr/lib*/**/libroughscope_core.a"))
    assert archives, "libroughscope-dev holds no static library"
    # Not stripped of its symbols (CPACK_STRIP_FILES must leave archives linkable).
    assert " T " in sh(["nm", "--defined-only", archives[0]])
    assert (root / "usr" / "include" / "roughscope" / "version.hpp").read_text().count(
        f'"{project_version()}"') == 1
