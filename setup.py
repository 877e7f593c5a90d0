"""setuptools side of `pip install .` / `python3 -m build` (pyproject.toml).

The package is python/roughscope/ plus its compiled module roughscope._core, which CMake builds
(the project's one build: CMakeLists.txt) with the library, the CLI, tests and benchmarks off.
The version is the one in CMakeLists.txt's project() call, the single source of every version.

Environment:
  ROUGHSCOPE_CMAKE_BUILD_DIR  the CMake build folder (default build-python/cmake beside this file);
                              an existing configured folder is reused
  CMAKE_ARGS                  extra arguments for the CMake configure step (e.g. -DCMAKE_BUILD_TYPE=Debug)
  ROUGHSCOPE_WERROR           ON: warnings are errors (as in CI)
  CMAKE_BUILD_PARALLEL_LEVEL  parallel compile jobs (default: the number of CPUs)
ccache is used when installed (CCACHE_BASEDIR defaults to this folder, so another clone's or the
`make build` folder's objects are reused).
"""
import os
import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = Path(__file__).resolve().parent


def project_version() -> str:
    text = (ROOT / "CMakeLists.txt").read_text(encoding="utf-8")
    match = re.search(r"project\(\s*roughscope\s+VERSION\s+([0-9]+\.[0-9]+\.[0-9]+)", text)
    if not match:
        raise RuntimeError("CMakeLists.txt: project(roughscope VERSION x.y.z) not found")
    return match.group(1)


class CMakeExtension(Extension):
    def __init__(self, name: str):
        super().__init__(name, sources=[])


class CMakeBuild(build_ext):
    """Builds roughscope._core with CMake and puts it where setuptools packs the extension."""

    def build_extension(self, ext: Extension) -> None:
        build_dir = Path(os.environ.get("ROUGHSCOPE_CMAKE_BUILD_DIR")
                         or ROOT / "build-python" / "cmake").resolve()
        build_dir.mkdir(parents=True, exist_ok=True)
        env = dict(os.environ)
        configure = ["cmake", "-S", str(ROOT), "-B", str(build_dir),
                     "-DCMAKE_BUILD_TYPE=Release",
                     "-DROUGHSCOPE_BUILD_PYTHON=ON", "-DROUGHSCOPE_BUILD_CLI=OFF",
                     "-DROUGHSCOPE_BUILD_TESTS=OFF", "-DROUGHSCOPE_BUILD_BENCH=OFF",
                     "-DROUGHSCOPE_BUILD_FUZZERS=OFF", "-DROUGHSCOPE_SANITIZE=OFF",
                     f"-DROUGHSCOPE_WERROR={os.environ.get('ROUGHSCOPE_WERROR', 'OFF')}",
                     f"-DPython3_EXECUTABLE={sys.executable}"]
        if not (build_dir / "CMakeCache.txt").exists() and shutil.which("ninja"):
            configure += ["-G", "Ninja"]
        if shutil.which("ccache"):
            configure.append("-DCMAKE_CXX_COMPILER_LAUNCHER=ccache")
            env.setdefault("CCACHE_BASEDIR", str(ROOT))
        configure += shlex.split(os.environ.get("CMAKE_ARGS", ""))
        jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL") or str(os.cpu_count() or 1)
        subprocess.run(configure, check=True, env=env)
        subprocess.run(["cmake", "--build", str(build_dir), "--target", "_core", "-j", jobs],
                       check=True, env=env)
        built = sorted((build_dir / "python" / "roughscope").glob("_core*.so"))
        if not built:
            raise RuntimeError(f"CMake built no roughscope/_core*.so in {build_dir / 'python'}")
        target = Path(self.get_ext_fullpath(ext.name))
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(built[0], target)


# setuptools' own working folders stay out of the source tree's `build/` (make build's folder).
(ROOT / "build-python").mkdir(exist_ok=True)
setup(
    version=project_version(),
    package_dir={"": "python"},
    packages=["roughscope"],
    ext_modules=[CMakeExtension("roughscope._core")],
    cmdclass={"build_ext": CMakeBuild},
    zip_safe=False,
    options={"build": {"build_base": "build-python/setuptools"},
             "egg_info": {"egg_base": "build-python"}},
)
