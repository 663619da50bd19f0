"""Build a Python FMU's own linux64 binary (pi_speed.fmu) and put it, with what it needs, into the FMU.

Build time only (never bundled). Three steps, used by ``python_fmu.build``:

1. ``privatize(staging, package, script_stem)``: before pythonfmu packs the
   staged files, rename the bundled package ``cam_fmu`` to
   ``cam_fmu_<8 hex>`` and the slave script to ``pi_speed_fmu_slave_<8 hex>``
   (a hash of everything that runs inside the FMU), rewriting the slave's
   absolute ``cam_fmu`` imports. Neither a host's own cam_fmu nor another
   Python FMU in the same process can then shadow the bundled modules.
2. ``build_binary(dest_so)``: compile ``fmi2_python.c`` with the system C
   compiler (``$CC``, else ``cc``/``gcc``/``clang``) against the headers of the
   Python that runs the build. No compiler: ``NativeBuildError`` (no silent
   fallback to pythonfmu's binary on linux64).
3. ``install(fmu, names)``: swap ``binaries/linux64/<id>.so`` for the new
   binary, write ``resources/python.txt`` (where the build's Python is) and
   ``resources/native.txt`` (private names), move pythonfmu's run-time modules
   into the private package (``<package>._pythonfmu``) and add the bridge
   (``<package>._fmi_bridge``). pythonfmu's win64 binary stays as it is.

"""
from __future__ import annotations

import hashlib
import io
import os
import re
import shutil
import site
import subprocess
import sys
import sysconfig
import tempfile
import zipfile
from dataclasses import dataclass
from pathlib import Path
from typing import Dict, List, Optional

HERE = Path(__file__).resolve().parent
C_SOURCE = HERE / "fmi2_python.c"
BRIDGE = HERE / "bridge.py"
# pythonfmu modules the slave needs at run time (not its builder)
PYTHONFMU_RUNTIME = ("fmi2slave.py", "logmsg.py", "default_experiment.py", "_version.py", "enums.py",
                     "variables.py")
PRIVATE_PYTHONFMU = "_pythonfmu"
PRIVATE_INIT = '''"""pythonfmu's run-time part, private to this FMU (copied by cam_fmu/fmu/native/compile.py)."""
from ._version import __version__
from .enums import Fmi2Causality, Fmi2Initial, Fmi2Variability
from .fmi2slave import Fmi2Slave
from .variables import Boolean, Integer, Real, String
from .default_experiment import DefaultExperiment
'''


class NativeBuildError(RuntimeError):
    pass


@dataclass(frozen=True)
class PrivateNames:
    package: str        # e.g. cam_fmu_1a2b3c4d
    slave_module: str   # e.g. camdrive_fmu_slave_1a2b3c4d
    digest: str         # the 8 hex digits


def _pythonfmu_dir() -> Path:
    import pythonfmu
    return Path(pythonfmu.__file__).resolve().parent


def _rewrite_imports(source: str, old: str, new: str) -> str:
    """``import old``/``from old[.x] import`` -> the same with ``new`` (line starts only)."""
    source = re.sub(rf"^(\s*from\s+){re.escape(old)}(?=[\s.])", rf"\g<1>{new}", source, flags=re.M)
    return re.sub(rf"^(\s*import\s+){re.escape(old)}(?=[\s.,]|$)", rf"\g<1>{new}", source, flags=re.M)


def content_digest(staging: Path, package: str, script: Path) -> str:
    """8 hex digits of a hash over everything that runs inside the FMU."""
    h = hashlib.sha256()
    files = sorted((staging / package).rglob("*.py")) + [script, C_SOURCE, BRIDGE]
    files += [_pythonfmu_dir() / name for name in PYTHONFMU_RUNTIME]
    for path in files:
        h.update(path.name.encode() + b"\0" + path.read_bytes() + b"\0")
    return h.hexdigest()[:8]


def privatize(staging: Path, package: str, script_stem: str) -> PrivateNames:
    """Rename the staged package and slave script to private names (see the module doc)."""
    script = staging / f"{script_stem}.py"
    digest = content_digest(staging, package, script)
    names = PrivateNames(f"{package}_{digest}", f"{script_stem}_{digest}", digest)
    (staging / package).rename(staging / names.package)
    text = _rewrite_imports(script.read_text(encoding="utf-8"), package, names.package)
    (staging / f"{names.slave_module}.py").write_text(text, encoding="utf-8")
    script.unlink()
    for path in (staging / names.package).rglob("*.py"):  # bundled modules must use relative imports
        src = path.read_text(encoding="utf-8")
        fixed = _rewrite_imports(src, package, names.package)
        if fixed != src:
            path.write_text(fixed, encoding="utf-8")
    return names


def find_compiler() -> str:
    for candidate in filter(None, (os.environ.get("CC"), "cc", "gcc", "clang")):
        path = shutil.which(candidate.split()[0])
        if path:
            return path
    raise NativeBuildError("no C compiler found (tried $CC, cc, gcc, clang): cam.fmu's linux64 binary is built "
                           "from C source. Install one (./setup.sh does: apt-get install gcc) and build again.")


def build_binary(dest_so: Path, include_dir: Optional[Path] = None, compiler: Optional[str] = None,
                 extra_flags: List[str] = ()) -> Path:
    """Compile fmi2_python.c into ``dest_so`` and return it."""
    if not sys.platform.startswith("linux"):
        raise NativeBuildError(f"the native binary is built on linux only (this is {sys.platform})")
    cc = compiler or find_compiler()
    include = Path(include_dir or sysconfig.get_paths()["include"])
    if not (include / "Python.h").is_file():
        raise NativeBuildError(f"Python.h not found in {include}: install the Python development headers")
    dest_so = Path(dest_so)
    dest_so.parent.mkdir(parents=True, exist_ok=True)
    cmd = [cc, "-shared", "-fPIC", "-O2", "-g", "-Wall", "-Wextra", "-Wno-format-truncation", "-fvisibility=hidden",
           f"-I{include}", str(C_SOURCE), "-o", str(dest_so), "-ldl", "-lpthread", *extra_flags]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode != 0:
        raise NativeBuildError(f"compiling {C_SOURCE.name} failed:\n{' '.join(cmd)}\n{proc.stderr}")
    return dest_so


def python_location() -> Dict[str, object]:
    """Where the Python running the build lives (the FMU's binary loads this one in native hosts)."""
    v = sysconfig.get_config_var
    libdir = v("LIBDIR") or ""
    soname = v("INSTSONAME") or v("LDLIBRARY") or ""
    libpython = os.path.join(libdir, soname)
    if not v("Py_ENABLE_SHARED") or not os.path.isfile(libpython):
        raise NativeBuildError(f"this Python ({sys.executable}) has no shared libpython ({libpython}); native hosts "
                               "need one: use a Python built with --enable-shared")
    sites = list(dict.fromkeys(site.getsitepackages() + [sysconfig.get_paths()["purelib"],
                                                         sysconfig.get_paths()["platlib"]]))
    return {"executable": sys.executable, "libpython": libpython, "home": sys.base_prefix,
            "version": "%d.%d" % sys.version_info[:2], "site": sites}


def python_txt(location: Dict[str, object]) -> str:
    lines = ["# Python used by cam.fmu's linux64 binary in hosts that run no Python of their own.",
             "# Written at build time; the environment variable CAM_FMU_PYTHON (a python executable",
             "# or a libpython) overrides this file. It needs numpy in one of the site folders.",
             f"version={location['version']}",
             f"executable={location['executable']}",
             f"libpython={location['libpython']}",
             f"home={location['home']}"]
    lines += [f"site={s}" for s in location["site"]]
    return "\n".join(lines) + "\n"


def install(fmu: Path, names: PrivateNames, binary: Optional[Path] = None,
            location: Optional[Dict[str, object]] = None) -> Path:
    """Put the native binary and its resources into the built FMU ``fmu`` (rewritten in place)."""
    import xml.etree.ElementTree as ET
    fmu = Path(fmu)
    location = location or python_location()
    with tempfile.TemporaryDirectory(prefix="cam_fmu_native_") as tmp:
        if binary is None:
            binary = build_binary(Path(tmp) / "fmu.so")
        with zipfile.ZipFile(fmu) as zin:
            entries = [(info.filename, zin.read(info.filename)) for info in zin.infolist()]
        md = ET.fromstring(dict(entries)["modelDescription.xml"])
        identifier = md.find("CoSimulation").get("modelIdentifier")
        out: List[tuple] = []
        seen_so = False
        for name, data in entries:
            if name.startswith("resources/pythonfmu/"):
                base = name.rsplit("/", 1)[1]
                if base in PYTHONFMU_RUNTIME:
                    out.append((f"resources/{names.package}/{PRIVATE_PYTHONFMU}/{base}", data))
                continue  # the builder and CLI of pythonfmu are not needed at run time
            if name == f"resources/{names.slave_module}.py":
                data = _rewrite_imports(data.decode("utf-8"), "pythonfmu",
                                        f"{names.package}.{PRIVATE_PYTHONFMU}").encode("utf-8")
            if name == f"binaries/linux64/{identifier}.so":
                data = Path(binary).read_bytes()
                seen_so = True
            out.append((name, data))
        if not seen_so:
            raise NativeBuildError(f"the FMU has no binaries/linux64/{identifier}.so to replace")
        out.append((f"resources/{names.package}/{PRIVATE_PYTHONFMU}/__init__.py", PRIVATE_INIT.encode()))
        out.append((f"resources/{names.package}/_fmi_bridge.py", BRIDGE.read_bytes()))
        out.append(("resources/native.txt",
                    f"package={names.package}\nslave_module={names.slave_module}\n".encode()))
        out.append(("resources/python.txt", python_txt(location).encode()))
        buffer = io.BytesIO()
        with zipfile.ZipFile(buffer, "w", compression=zipfile.ZIP_DEFLATED) as zout:
            for name, data in out:
                info = zipfile.ZipInfo(name, date_time=(2020, 1, 1, 0, 0, 0))
                info.compress_type = zipfile.ZIP_DEFLATED
                info.external_attr = (0o755 if name.endswith(".so") else 0o644) << 16
                zout.writestr(info, data)
        fmu.write_bytes(buffer.getvalue())
    return fmu


if __name__ == "__main__":  # python -m cam_fmu.fmu.native.compile DEST.so
    print(build_binary(Path(sys.argv[1] if len(sys.argv) > 1 else "cam.so")))
