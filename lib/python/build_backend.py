"""The build backend of `pip install .` (PEP 517, pyproject.toml): builds the module with the project's
CMake build and packs it as a wheel, with nothing to download (no build requirements), so that pip
works offline from Debian's packages into a virtual environment or the user site.

The module is compiled for the interpreter that runs pip (its headers: Debian's python3-dev) in
build/pip of the checkout, reused by the next install; BODYPOINT_BUILD_DIR names another build tree
(an existing `cmake -B build`, whose module is then only brought up to date).
"""
import base64
import hashlib
import os
import pathlib
import re
import subprocess
import sys
import sysconfig
import zipfile

SOURCE = pathlib.Path(__file__).resolve().parents[2]
NAME = "bodypoint"


def _version():
    text = (SOURCE / "CMakeLists.txt").read_text()
    return re.search(r"project\(bodypoint VERSION ([0-9.]+)", text).group(1)


def _tag():
    """The wheel's tag for this interpreter: cpXY-cpXY-<platform>."""
    py = f"cp{sys.version_info[0]}{sys.version_info[1]}"
    platform = sysconfig.get_platform().replace("-", "_").replace(".", "_")
    return f"{py}-{py}{sys.abiflags}-{platform}"


def _build_module():
    """Configures (once) and builds the _bodypoint target; returns the build's python folder."""
    build = pathlib.Path(os.environ.get("BODYPOINT_BUILD_DIR") or SOURCE / "build" / "pip")
    # pip's isolated build hides the system's site-packages through PYTHONPATH; a configure that CMake
    # re-runs inside it (an edited CMakeLists or __init__.py) would find no numpy, pytest or matplotlib
    # and leave the build tree's Python tests out.
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONNOUSERSITE", "PYTHONHOME")}
    if not (build / "CMakeCache.txt").exists():
        subprocess.run(["cmake", "-S", str(SOURCE), "-B", str(build), "-G", "Ninja", "-DCMAKE_BUILD_TYPE=Release",
                        f"-DBODYPOINT_PYTHON_EXECUTABLE={sys.executable}", f"-DPython3_EXECUTABLE={sys.executable}"],
                       check=True, stdout=sys.stderr, env=env)
    subprocess.run(["cmake", "--build", str(build), "--target", "_bodypoint"], check=True, stdout=sys.stderr, env=env)
    return build / "python" / NAME


def _metadata():
    return (f"Metadata-Version: 2.1\nName: {NAME}\nVersion: {_version()}\n"
            "Summary: Dynamics of a body-point (a particle with translation and rotation) in Coulomb fields\n"
            "License: MIT\nRequires-Python: >=3.9\nRequires-Dist: numpy\n")


def _record_line(path, data):
    digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
    return f"{path},sha256={digest},{len(data)}"


def get_requires_for_build_wheel(config_settings=None):
    return []


def prepare_metadata_for_build_wheel(metadata_directory, config_settings=None):
    info = pathlib.Path(metadata_directory) / f"{NAME}-{_version()}.dist-info"
    info.mkdir(parents=True, exist_ok=True)
    (info / "METADATA").write_text(_metadata())
    return info.name


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    module = _build_module()
    files = {f"{NAME}/__init__.py": (SOURCE / "lib" / "python" / NAME / "__init__.py").read_bytes()}
    for so in module.glob("_bodypoint*.so"):
        files[f"{NAME}/{so.name}"] = so.read_bytes()
    if len(files) != 2:
        raise RuntimeError(f"the build left no single _bodypoint module in {module}")
    info = f"{NAME}-{_version()}.dist-info"
    files[f"{info}/METADATA"] = _metadata().encode()
    files[f"{info}/WHEEL"] = (f"Wheel-Version: 1.0\nGenerator: bodypoint build_backend\nRoot-Is-Purelib: false\n"
                              f"Tag: {_tag()}\n").encode()
    record = [_record_line(path, data) for path, data in files.items()] + [f"{info}/RECORD,,"]
    files[f"{info}/RECORD"] = ("\n".join(record) + "\n").encode()
    name = f"{NAME}-{_version()}-{_tag()}.whl"
    with zipfile.ZipFile(pathlib.Path(wheel_directory) / name, "w", zipfile.ZIP_DEFLATED) as wheel:
        for path, data in files.items():
            wheel.writestr(path, data)
    return name
