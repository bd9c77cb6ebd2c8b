"""The self-contained wheel (.ci/build-wheel): its manylinux tag, every shared object resolving
inside the wheel or to the system libraries a wheel may use, licences for what it bundles, a C++
plugin built against it, and a fresh Debian root filesystem with no compiler and no -dev package
where an unprivileged user installs it offline, checks it with `ambfplus doctor`, records the
demo, and, once Mesa's EGL driver is removed, hears from `ambfplus doctor` what to install.

The wheel is built once per session from this repository (under half a minute on a warm build
tree), or taken from AMBFPLUS_WHEEL. The root filesystem test needs root, debootstrap and the Debian
mirror apt uses; it skips with the reason where any is missing."""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import time
import urllib.request
import zipfile
from pathlib import Path

import pytest
from helpers.wheel_tools import (
    REPO,
    download_wheelhouse,
    glibc_version,
    install_into_new_venv,
    wheel_or_build,
)

auditwheel = pytest.importorskip("auditwheel", reason="needs auditwheel (pip: ambfplus[test])")
elftools = pytest.importorskip("elftools", reason="needs pyelftools (comes with auditwheel)")
from elftools.elf.dynamic import DynamicSection  # noqa: E402
from elftools.elf.elffile import ELFFile  # noqa: E402

# Builds the wheel and checks it in fresh environments: minutes.
pytestmark = pytest.mark.packaging

# The GL vendor-neutral dispatch libraries: the system's (the driver sits behind them).
GL_DISPATCH = {"libEGL.so.1", "libOpenGL.so.0", "libGL.so.1"}
# What the engine needs bundled (original file names, before auditwheel's hash).
MUST_BUNDLE = ("libBulletDynamics", "libBulletCollision", "libBulletSoftBody", "libLinearMath",
               "libassimp", "libyaml-cpp", "libpng16", "libjpeg", "libepoxy")  # fmt: skip
# Licences that let the wheel be used, changed and shipped on without copyleft terms (Debian's
# short names, lower case): MIT and BSD kinds, Apache, Boost, zlib and libpng's, the Independent
# JPEG Group's (BSD-BY-LC-NE), and the notices some files carry (Elsevier's for the code from
# "Real-Time Collision Detection", NTP, public domain).
PERMISSIVE = set(
    "expat mit x11 bsd-2-clause bsd-3-clause apache-2.0 apache-2 bsl-1.0 bsl-1 zlib libpng "
    "libpng-2.0 bsd-by-lc-ne ijg elsevier-cdrom-license ntp public-domain "
    "gnu-all-permissive-license".split()
)
# Files a copyright file lists that are not part of the library bundled from it, as (Debian
# package, file) patterns: Debian's packaging, Bullet's build-time tool, libpng's example
# programs, Draco's test data.
NOT_IN_THE_LIBRARY = ((r".*", r"debian/.*"), (r"libbullet.*", r"Extras/Serialize/makesdna/.*"),
                      (r"libpng.*", r"contrib/.*"), (r"libdraco.*", r"testdata/.*"))  # fmt: skip
# The packages the issue allows in the root filesystem: Python, glvnd and Mesa's drivers.
ROOTFS_PACKAGES = ("python3", "python3-venv", "libegl1", "libopengl0", "libegl-mesa0",
                   "libgl1-mesa-dri")  # fmt: skip
SIM_UID = 4242


@pytest.fixture(scope="session")
def wheel(tmp_path_factory) -> Path:
    if not os.environ.get("AMBFPLUS_WHEEL") and not (REPO / ".ci" / "build-wheel").is_file():
        pytest.skip("no wheel: set AMBFPLUS_WHEEL or run from the repository (.ci/build-wheel)")
    return wheel_or_build(tmp_path_factory.mktemp("wheel"))


@pytest.fixture(scope="session")
def unpacked(wheel, tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("unpacked")
    with zipfile.ZipFile(wheel) as archive:
        archive.extractall(folder)
    return folder


@pytest.fixture(scope="session")
def auditwheel_show(wheel):
    """`auditwheel show` started at once (it takes a minute) and collected when needed."""
    process = subprocess.Popen(
        [sys.executable, "-m", "auditwheel", "show", str(wheel)],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    yield process
    if process.poll() is None:
        process.kill()
        process.wait()


def platform_tag(wheel: Path) -> str:
    """The platform tag of a wheel's file name."""
    return wheel.name[: -len(".whl")].split("-")[-1]


def policy_whitelist(tag: str) -> set[str]:
    """The libraries auditwheel's policy for this tag lets a wheel take from the system."""
    policies = json.loads(
        (Path(auditwheel.__file__).parent / "policy" / "manylinux-policy.json").read_text()
    )
    name = re.sub(r"_x86_64$", "", tag)
    (policy,) = [p for p in policies if p["name"] == name or name in p.get("aliases", [])]
    return set(policy["lib_whitelist"])


def elf_dependencies(path: Path) -> tuple[list[str], list[str]]:
    """The NEEDED entries and the RUNPATH (or RPATH) folders of an ELF file."""
    needed, paths = [], []
    with open(path, "rb") as f:
        for section in ELFFile(f).iter_sections():
            if isinstance(section, DynamicSection):
                for tag in section.iter_tags():
                    if tag.entry.d_tag == "DT_NEEDED":
                        needed.append(tag.needed)
                    elif tag.entry.d_tag == "DT_RUNPATH":
                        paths += tag.runpath.split(":")
                    elif tag.entry.d_tag == "DT_RPATH":
                        paths += tag.rpath.split(":")
    return needed, paths


def shared_objects(folder: Path) -> list[Path]:
    found = []
    for path in sorted(folder.rglob("*.so*")):
        if path.is_file() and path.read_bytes()[:4] == b"\x7fELF":
            found.append(path)
    return found


def test_auditwheel_reports_the_manylinux_tag_of_the_file_name(wheel, auditwheel_show):
    output, _ = auditwheel_show.communicate(timeout=900)
    assert auditwheel_show.returncode == 0, output
    match = re.search(r'consistent\s+with\s+the\s+following\s+platform\s+tag:\s+"([^"]+)"', output)
    assert match, output
    assert match.group(1).startswith("manylinux_"), output
    assert match.group(1) == platform_tag(wheel)


def test_every_shared_object_resolves_inside_the_wheel_or_to_allowed_system_libraries(
    wheel, unpacked
):
    # glibc's own loader is part of glibc, which the policy's list names by its libraries.
    allowed = policy_whitelist(platform_tag(wheel)) | GL_DISPATCH | {"ld-linux-x86-64.so.2"}
    objects = shared_objects(unpacked)
    assert len(objects) >= len(MUST_BUNDLE) + 3, "the engine, its module, a plugin, its libraries"
    outside: dict[str, set[str]] = {}
    for elf in objects:
        needed, runpath = elf_dependencies(elf)
        folders = [Path(p.replace("$ORIGIN", str(elf.parent))).resolve() for p in runpath]
        for name in needed:
            inside = [f / name for f in folders if (f / name).is_file()]
            if inside:
                assert inside[0].resolve().is_relative_to(unpacked.resolve()), (elf, name)
                continue
            outside.setdefault(name, set()).add(elf.name)
    not_allowed = {name: users for name, users in outside.items() if name not in allowed}
    assert not not_allowed, f"needed from the system but not allowed there: {not_allowed}"
    # The engine's own libraries are found through $ORIGIN, never from the system.
    assert "libambfplus.so" not in outside
    bundled = [p.name for p in (unpacked / "ambfplus.libs").iterdir()]
    for library in MUST_BUNDLE:
        assert any(re.match(rf"{re.escape(library)}-[0-9a-f]{{8}}\.", b) for b in bundled), library
    assert not [b for b in bundled if b.split("-")[0] in {"libEGL", "libOpenGL", "libGL"}]


def test_every_bundled_library_comes_with_its_licence(unpacked):
    (dist_info,) = unpacked.glob("ambfplus-*.dist-info")
    licences = dist_info / "licenses" / "third_party"
    manifest = json.loads((licences / "third_party.json").read_text())
    listed = {entry["file"]: entry for entry in manifest["libraries"]}
    bundled = {f"ambfplus.libs/{p.name}" for p in (unpacked / "ambfplus.libs").iterdir()}
    assert bundled == set(listed)
    for entry in listed.values():
        text = (dist_info / "licenses" / entry["license_file"]).read_text(errors="replace")
        assert "Copyright" in text or "copyright" in text, entry["license_file"]
    # Eigen's headers ship for plugins, with their licence.
    assert (unpacked / "ambfplus" / "include" / "eigen3" / "Eigen" / "Core").is_file()
    assert "MPL" in (licences / "eigen3.copyright").read_text()


def copyright_stanzas(text: str) -> list[tuple[list[str], str]]:
    """(file patterns, licence expression) of each Files stanza of a machine-readable Debian
    copyright file."""
    stanzas = []
    for stanza in re.split(r"\n[ \t]*\n", text):
        files = re.search(r"^Files:((?:.*)(?:\n[ \t]+.*)*)", stanza, flags=re.MULTILINE)
        licence = re.search(r"^License:[ \t]*(\S.*)$", stanza, flags=re.MULTILINE)
        if files and licence:
            stanzas.append((files.group(1).split(), licence.group(1).strip()))
    return stanzas


def is_permissive(expression: str) -> bool:
    """Whether a licence expression ("A or B", "A and B", names in any case) leaves no copyleft
    term: one permissive choice of an "or", every part of an "and"."""
    choices = re.split(r"\s+or\s+", expression, flags=re.IGNORECASE)
    return any(
        all(
            part.strip().lower() in PERMISSIVE
            for part in re.split(r"\s+and\s+", choice, flags=re.IGNORECASE)
        )
        for choice in choices
    )


def test_is_permissive_reads_licence_expressions():
    assert is_permissive("Zlib and Elsevier-CDROM-License")
    assert is_permissive("libpng OR Apache-2.0 OR BSD-3-clause")
    assert not is_permissive("GPL-2+")
    assert not is_permissive("Expat and LGPL-2.1+")
    assert is_permissive("GPL-2+ or Expat")
    assert not is_permissive("CC-BY-SA-4.0")  # unknown names are not assumed permissive


def test_every_bundled_library_is_permissively_licensed(unpacked):
    (dist_info,) = unpacked.glob("ambfplus-*.dist-info")
    licences = dist_info / "licenses"
    manifest = json.loads((licences / "third_party" / "third_party.json").read_text())
    flagged = {}
    for entry in manifest["libraries"]:
        text = (licences / entry["license_file"]).read_text(errors="replace")
        stanzas = copyright_stanzas(text)
        assert stanzas, f"{entry['license_file']} is not a machine-readable copyright file"
        for files, expression in stanzas:
            outside = [f for p, f in NOT_IN_THE_LIBRARY if re.fullmatch(p, entry["debian_package"])]
            if all(any(re.fullmatch(pattern, f) for pattern in outside) for f in files):
                continue
            if not is_permissive(expression):
                flagged.setdefault(entry["soname"], []).append(
                    f"{' '.join(files)[:80]}: {expression}"
                )
    assert not flagged, f"copyleft or unknown licences in bundled libraries: {flagged}"
    # None of the heavy, copyleft-carrying stacks a general image library brings.
    bundled = [p.name for p in (unpacked / "ambfplus.libs").iterdir()]
    heavy = ("libopencv", "libgdal", "libgdcm", "libpoppler", "libx265", "libavcodec", "libGLX")
    assert not [b for b in bundled if b.startswith(heavy)], bundled


@pytest.fixture(scope="session")
def host_venv(wheel, tmp_path_factory) -> Path:
    """A venv without the machine's packages, the wheel installed in it offline."""
    folder = tmp_path_factory.mktemp("wheel_venv")
    try:
        wheelhouse = download_wheelhouse(
            wheel, folder / "wheelhouse", sys.version_info[:2], glibc_version()
        )
    except RuntimeError as error:
        pytest.skip(f"cannot download the wheel's dependencies: {error}")
    python, _ = install_into_new_venv(folder / "venv", wheel, wheelhouse)
    return python


def test_a_cpp_plugin_builds_against_the_installed_wheel(host_venv, tmp_path):
    cmake, compiler = shutil.which("cmake"), shutil.which("c++") or shutil.which("g++")
    if cmake is None or compiler is None:
        pytest.skip("building a plugin needs cmake and a C++ compiler")
    # Run from elsewhere: in the repository, `-m ambfplus` would find the source folder.
    printed = subprocess.run(
        [str(host_venv), "-m", "ambfplus", "--cmake-dir"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )
    assert printed.returncode == 0, printed.stderr
    cmake_dir = printed.stdout.strip()
    site = Path(cmake_dir).parents[1]
    assert Path(cmake_dir).is_relative_to(host_venv.parents[1])
    build = tmp_path / "build"
    subprocess.run([cmake, "-S", str(REPO / "plugins" / "body_spinner"), "-B", str(build),
                    f"-Dambfplus_DIR={cmake_dir}", "-DCMAKE_BUILD_TYPE=Release",
                    "-DCMAKE_EXPORT_COMPILE_COMMANDS=ON"],
                   check=True, capture_output=True)  # fmt: skip
    built = subprocess.run([cmake, "--build", str(build), "-j2"], capture_output=True, text=True)
    assert built.returncode == 0, built.stdout + built.stderr
    # Eigen comes from the wheel, not from a system -dev package.
    command = json.loads((build / "compile_commands.json").read_text())[0]["command"]
    assert f"{site}/ambfplus/include/eigen3" in command, command
    assert "/usr/include/eigen3" not in command
    plugin = build / "libbody_spinner.so"
    # Loaded into the wheel's engine, it turns a body a quarter turn in a simulated second.
    script = f"""
import numpy as np, ambfplus
world = ambfplus.World()
ball = world.add_body("ball", "box", size=(0.1, 0.2, 0.3), mass=1.0)
world.load_plugin({str(plugin)!r}, ball)
world.step(1000)
print(np.round(ball.pose[:3, :3], 6).tolist())
"""
    result = subprocess.run([str(host_venv), "-c", script], capture_output=True, text=True,
                            cwd=tmp_path)  # fmt: skip
    assert result.returncode == 0, result.stderr
    rotation = json.loads(result.stdout.strip().splitlines()[-1])
    quarter = [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
    assert max(abs(a - b) for r, q in zip(rotation, quarter) for a, b in zip(r, q)) < 1e-2


# The root filesystem test.


def debian_mirror() -> tuple[str, str]:
    """(mirror URL, release codename) of the main Debian archive apt uses here."""
    codename = ""
    for line in Path("/etc/os-release").read_text().splitlines():
        if line.startswith("VERSION_CODENAME="):
            codename = line.split("=", 1)[1].strip('"')
    sources = [Path("/etc/apt/sources.list"), *sorted(Path("/etc/apt/sources.list.d").glob("*"))]
    for source in sources:
        if not source.is_file():
            continue
        text = source.read_text()
        # deb822 stanzas (URIs: / Suites:) and one-line entries (deb URI suite components).
        for stanza in re.split(r"\n\s*\n", text):
            fields = dict(re.findall(r"^(\w[\w-]*):\s*(.*)$", stanza, flags=re.MULTILINE))
            if (
                "deb" in fields.get("Types", "").split()
                and codename in fields.get("Suites", "").split()
            ):
                return fields["URIs"].split()[0].rstrip("/"), codename
        for match in re.finditer(r"^deb\s+(?:\[[^\]]*\]\s+)?(\S+)\s+(\S+)", text, re.MULTILINE):
            if match.group(2) == codename:
                return match.group(1).rstrip("/"), codename
    raise LookupError(f"no apt source for the Debian release {codename!r}")


def mounts_below(root: Path) -> list[str]:
    """Mount points at or under `root` (from /proc/self/mounts)."""
    prefix = str(root.resolve())
    points = [line.split()[1] for line in Path("/proc/self/mounts").read_text().splitlines()]
    return [p for p in points if p == prefix or p.startswith(prefix + "/")]


@pytest.fixture
def rootfs(tmp_path):
    """A minimal Debian root filesystem of this machine's release, made by debootstrap with
    only Python, glvnd and Mesa's drivers; /proc mounted while the test runs."""
    if os.geteuid() != 0:
        pytest.skip("making a root filesystem (debootstrap, chroot) needs root")
    if shutil.which("debootstrap") is None:
        pytest.skip("needs debootstrap (Debian: apt-get install debootstrap)")
    try:
        mirror, codename = debian_mirror()
        urllib.request.urlopen(f"{mirror}/dists/{codename}/Release", timeout=15).close()
    except (LookupError, OSError) as error:
        pytest.skip(f"no Debian mirror to make a root filesystem from: {error}")
    root = tmp_path / "root"
    root.mkdir()
    # Downloaded packages are kept between runs (and clones), so later runs download nothing.
    cache_home = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
    cache = cache_home / "ambfplus" / "debootstrap"
    cache.mkdir(parents=True, exist_ok=True)
    try:
        # In memory: dpkg's many fsyncs cost nothing there, and removing it is one unmount
        # (deleting its 15,000 files from disk took longer than the demo).
        subprocess.run(["mount", "-t", "tmpfs", "-o", "size=3g,mode=755", "rootfs", str(root)],
                       check=True)  # fmt: skip
        made = subprocess.run(
            ["debootstrap", "--variant=minbase", f"--include={','.join(ROOTFS_PACKAGES)}",
             f"--cache-dir={cache}", codename, str(root), mirror],
            capture_output=True, text=True,
        )  # fmt: skip
        if made.returncode != 0:
            log = root / "debootstrap" / "debootstrap.log"
            detail = log.read_text()[-3000:] if log.is_file() else made.stderr[-3000:]
            pytest.fail(f"debootstrap failed:\n{detail}")
        subprocess.run(["mount", "-t", "proc", "proc", str(root / "proc")], check=True)
        subprocess.run(["mount", "-t", "tmpfs", "-o", "size=256m", "shm", str(root / "dev/shm")],
                       check=True)  # fmt: skip
        subprocess.run(["chroot", str(root), "useradd", "--create-home", "--uid", str(SIM_UID),
                        "sim"], check=True)  # fmt: skip
        yield root
    finally:
        for point in sorted(mounts_below(root), key=len, reverse=True):
            subprocess.run(["umount", point], check=False)
        left = mounts_below(root)
        if left:  # never delete through a mount
            pytest.fail(f"could not unmount {left}")
        shutil.rmtree(root, ignore_errors=True)


def as_sim(root: Path, command: str, env: dict[str, str] | None = None, timeout: float = 600):
    """Runs a shell command in the root filesystem as the unprivileged user `sim`, in a network
    namespace of its own (loopback only), so nothing there can reach the network."""
    environment = {"HOME": "/home/sim", "USER": "sim", "PATH": "/home/sim/venv/bin:/usr/bin:/bin",
                   "LANG": "C.UTF-8", **(env or {})}  # fmt: skip
    settings = [f"{key}={value}" for key, value in environment.items()]
    return subprocess.run(
        ["unshare", "--net", "chroot", f"--userspec={SIM_UID}:{SIM_UID}", str(root),
         "/usr/bin/env", "-i", *settings, "/bin/sh", "-c", f"cd /home/sim && {command}"],
        capture_output=True, text=True, timeout=timeout,
    )  # fmt: skip


def test_the_wheel_installs_and_records_the_demo_in_a_minimal_debian_as_a_user(
    wheel, rootfs, tmp_path
):
    root = rootfs
    # Nothing to build with: no compiler, no headers of the engine's libraries.
    assert not (root / "usr/bin/gcc").exists() and not (root / "usr/bin/c++").exists()
    assert not (root / "usr/include/eigen3").exists() and not (root / "usr/include/bullet").exists()
    versions = (
        "import platform as p, sys; print(*sys.version_info[:2], *p.libc_ver()[1].split('.'))"
    )
    python = subprocess.run(
        ["chroot", str(root), "python3", "-c", versions], capture_output=True, text=True, check=True
    ).stdout.split()
    python_version, glibc = (int(python[0]), int(python[1])), (int(python[2]), int(python[3]))
    dist = root / "dist"
    dist.mkdir()
    try:
        download_wheelhouse(wheel, dist, python_version, glibc)
    except RuntimeError as error:
        pytest.skip(f"cannot download the wheel's dependencies for the root filesystem: {error}")
    shutil.copy(wheel, dist)

    start = time.perf_counter()
    installed = as_sim(root, "python3 -m venv venv && venv/bin/pip install -q --no-index "
                             f"--find-links /dist /dist/{wheel.name}")  # fmt: skip
    assert installed.returncode == 0, installed.stdout + installed.stderr
    print(f"install in the root filesystem: {time.perf_counter() - start:.1f} s")

    # Every shared object of the installed package finds all it needs there.
    ldd = as_sim(root, "for f in $(find venv/lib -name '*.so*' -path '*ambfplus*'); do "
                       "ldd $f | sed \"s|^|$f: |\"; done")  # fmt: skip
    assert ldd.returncode == 0, ldd.stderr
    lines = ldd.stdout.splitlines()
    assert "not found" not in ldd.stdout, [x for x in lines if "not found" in x]
    assert len({line.split(": ", 1)[0] for line in lines}) >= len(MUST_BUNDLE) + 3, lines
    # The image libraries come from the wheel: the root filesystem has none.
    needs = [line.split(": ", 1)[1].split("=>") for line in lines if "=>" in line]
    for library in ("libpng16", "libjpeg", "libBulletDynamics"):
        found = [path for name, path in needs if name.strip().startswith(library)]
        assert found and all("/ambfplus.libs/" in path for path in found), (library, found)

    doctor = as_sim(root, "ambfplus doctor")
    assert doctor.returncode == 0, doctor.stdout + doctor.stderr
    assert "self-contained wheel" in doctor.stdout and "llvmpipe" in doctor.stdout

    demo = as_sim(root, "ambfplus demo --out demo --width 320 --height 240 --every 100")
    assert demo.returncode == 0, demo.stdout + demo.stderr
    checked = as_sim(root, "ambfplus validate demo/session.h5")
    assert checked.returncode == 0, checked.stdout + checked.stderr
    frame = json.loads((root / "home/sim/demo/frame.json").read_text())
    assert frame["recording"]["frames"] > 0 and frame["recording"]["voxels_removed"] > 0
    assert "llvmpipe" in frame["gl"]["renderer"]
    # The recording made inside validates with this machine's own package as well.
    here = subprocess.run(
        [sys.executable, "-m", "ambfplus", "validate", str(root / "home/sim/demo/session.h5")],
        capture_output=True, text=True, cwd=tmp_path,
    )  # fmt: skip
    assert here.returncode == 0, here.stdout + here.stderr

    # Without Mesa's EGL driver (its package removed, glvnd's dispatch library left), doctor
    # says so and how to fix it, and exits 1.
    removed = subprocess.run(
        ["chroot", str(root), "dpkg", "--remove", "--force-depends", "libegl-mesa0"],
        capture_output=True, text=True,
    )  # fmt: skip
    assert removed.returncode == 0, removed.stdout + removed.stderr
    assert not list((root / "usr/share/glvnd/egl_vendor.d").glob("*.json"))
    empty = as_sim(root, "ambfplus doctor")
    assert empty.returncode == 1, empty.stdout + empty.stderr
    assert "no EGL driver is installed" in empty.stdout
    assert "to fix: sudo apt-get install libegl-mesa0 libgl1-mesa-dri" in empty.stdout
    assert "cannot render here: EGL drivers, renderer" in empty.stdout
