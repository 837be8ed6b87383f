"""Fetch the real-drawing corpus and LinuxCNC's ``rs274`` from Debian packages.

Run from the repository root (``make corpus`` does)::

    python tests/corpus/fetch_corpus.py [--dest .corpus] [--refresh]

What it fetches, with ``apt-get download PKG`` and ``dpkg-deb -x`` (no root needed while the
apt lists exist; as root with no lists it runs ``apt-get update`` once):

- ``librecad-data``: LibreCAD's parts library, DXF drawn in LibreCAD
  (``usr/share/librecad/library``);
- ``tango-icon-theme``: the Tango icons, SVG drawn in Inkscape by many hands
  (``usr/share/icons/Tango/scalable``, symlinked aliases skipped);
- ``breeze-icon-theme``: KDE's Breeze icons, SVG with ``<style>`` sheets (a colour scheme
  applied by class, ``fill:currentColor``), a varied pick of those with a sheet
  (``usr/share/icons/breeze``);
- ``inkscape`` (optional, 20 MB download; only ``usr/share/inkscape/examples/*.svg`` is kept);
- ``openscad`` (3 MB download; only ``usr/share/openscad/examples/*/*.dxf`` is kept): the DXF
  outlines OpenSCAD's examples extrude, one layer per extruded part (``fan_side_center``);
- OpenSCAD's examples exported with ``openscad -o X.dxf`` — only when an ``openscad`` binary is
  already on PATH (the package pulls in Qt; it is not installed here), 2D examples only;
- ``linuxcnc-uspace`` + ``libboost-python1.74.0``: the ``rs274`` stand-alone G-code
  interpreter and the libraries it links (``libpython3.11``, ``libedit2`` too if the system
  lacks them), used by tests/corpus/test_rs274.py as an independent judge of linuxcnc output.

The result is ``DEST/manifest.json``: the file lists, paths relative to DEST (``full``, and
a deterministic, varied ``sample``, :data:`SAMPLE_SIZE` of each kind), and the ``rs274``
command. The script is
idempotent (a cached package is neither downloaded nor extracted again) and always exits 0:
when apt or the network is missing it says so and the corpus tests skip with that reason.
Nothing under DEST is ever committed (``.corpus/`` is in .gitignore).

The first fetch downloads about 50 MB of packages (about 250 MB in DEST once unpacked); ``make
test`` runs it. ``CAMTOOL_CORPUS=off`` (as for the corpus tests, which then skip) fetches
nothing and touches no network: ``CAMTOOL_CORPUS=off make test`` works offline at once.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import shutil
import subprocess
import sys
from collections.abc import Iterable
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
DEFAULT_DEST = ROOT / ".corpus"
MANIFEST = "manifest.json"
SAMPLE_SIZE = {"dxf": 30, "svg": 45}
"""Files of each kind in the sample, an equal share per source (15 SVGs each for three)."""
TANGO_ICONS = 60
BREEZE_ICONS = 60
MANIFEST_VERSION = 3
"""Raised when the sources change (2: Breeze added, 3: OpenSCAD's example DXFs); an older
cached manifest is rebuilt."""
OFF_SWITCH = "CAMTOOL_CORPUS"
"""The environment variable whose value ``off`` skips the fetch (and the corpus tests)."""

# Files kept out of the sample (still in CAMTOOL_CORPUS=full): one post of each took more
# than 2 s of CPU (valcnc, measured on the dev machine): art-nouveau-P3 8 s, rope-3D 3.3 s,
# eastern-motive-P4G, filters and tesselation-P3 over 20 s (Inkscape's tiled-clone
# examples). Seven targets times that is too long for `make test`.
HEAVY = {
    "art-nouveau-P3.svg",
    "eastern-motive-P4G.svg",
    "filters.svg",
    "rope-3D.svg",
    "tesselation-P3.svg",
}
LIBRECAD_DIR = "usr/share/librecad/library"
TANGO_DIR = "usr/share/icons/Tango/scalable"
INKSCAPE_DIR = "usr/share/inkscape/examples"
OPENSCAD_DIR = "usr/share/openscad/examples"
BREEZE_DIR = "usr/share/icons/breeze"
RS274 = "usr/bin/rs274"
# rs274's libraries that a plain Debian system lacks, by soname prefix -> package.
RS274_LIBS = {
    "libboost_python311": "libboost-python1.74.0",
    "libpython3.11": "libpython3.11",
    "libedit.so": "libedit2",
    "libtirpc": "libtirpc3",
}


class FetchError(Exception):
    """A package cannot be had (no apt, no network, no such package)."""


def log(msg: str) -> None:
    """Tell the user (stderr) what the fetch does."""
    print(f"fetch_corpus: {msg}", file=sys.stderr)


def _run(cmd: list[str], cwd: Path | None = None, timeout: float = 600) -> str:
    try:
        proc = subprocess.run(
            cmd, cwd=cwd, capture_output=True, text=True, timeout=timeout, check=False
        )
    except (OSError, subprocess.TimeoutExpired) as exc:
        raise FetchError(f"{cmd[0]}: {exc}") from exc
    if proc.returncode != 0:
        tail = (proc.stderr or proc.stdout).strip().splitlines()[-3:]
        raise FetchError(f"{' '.join(cmd)} failed: {' / '.join(tail)}")
    return proc.stdout


def _apt_ready() -> None:
    """Make sure ``apt-get download`` can work, or raise FetchError saying why not."""
    for tool in ("apt-get", "dpkg-deb"):
        if shutil.which(tool) is None:
            raise FetchError(f"'{tool}' is not available (not a Debian system?)")
    lists = Path("/var/lib/apt/lists")
    has_lists = lists.is_dir() and any(
        p.name.endswith("Packages.lz4") or "Packages" in p.name for p in lists.iterdir()
    )
    if not has_lists:
        if os.geteuid() != 0:
            raise FetchError("the apt package lists are missing; run 'apt-get update' as root")
        log("apt lists missing: running apt-get update")
        _run(["apt-get", "update", "-q"])


def fetch_deb(pkg: str, debs: Path) -> Path:
    """Download PKG's .deb into DEBS once; return its path."""
    have = sorted(debs.glob(f"{pkg}_*.deb"))
    if have:
        return have[-1]
    debs.mkdir(parents=True, exist_ok=True)
    log(f"downloading {pkg}")
    _run(["apt-get", "download", "-q", pkg], cwd=debs)
    have = sorted(debs.glob(f"{pkg}_*.deb"))
    if not have:
        raise FetchError(f"apt-get download {pkg} left no .deb")
    return have[-1]


def extract(deb: Path, dest: Path, members: Iterable[str] = ()) -> Path:
    """Extract DEB (or only MEMBERS, tar paths) into DEST once; return DEST."""
    stamp = dest / ".extracted"
    if stamp.exists() and stamp.read_text() == deb.name:
        return dest
    if dest.exists():
        shutil.rmtree(dest)
    dest.mkdir(parents=True)
    members = list(members)
    if members:
        tar = subprocess.Popen(["dpkg-deb", "--fsys-tarfile", str(deb)], stdout=subprocess.PIPE)
        subprocess.run(
            ["tar", "-x", "-C", str(dest), "--wildcards", *members], stdin=tar.stdout, check=False
        )
        tar.wait()
    else:
        _run(["dpkg-deb", "-x", str(deb), str(dest)])
    stamp.write_text(deb.name)
    return dest


def files_under(top: Path, suffix: str) -> list[Path]:
    """Regular (not symlinked) files under TOP ending in SUFFIX, sorted."""
    if not top.is_dir():
        return []
    return sorted(p for p in top.rglob(f"*{suffix}") if p.is_file() and not p.is_symlink())


def varied_sample(files: list[Path], top: Path, n: int) -> list[Path]:
    """Deterministic varied pick of N files: round-robin over folders, hashed order inside.

    Each folder (relative to TOP) is a category (LibreCAD's ``elektro/diode``, Tango's
    ``apps``...); its files are ordered by the SHA-1 of their relative path, and one file is
    taken from each folder in turn (folders in hashed order too), so the sample spans the
    categories and does not change unless the package does.
    """
    groups: dict[str, list[Path]] = {}
    for f in files:
        groups.setdefault(str(f.parent.relative_to(top)), []).append(f)
    for key, group in groups.items():
        groups[key] = sorted(group, key=lambda p: _digest(str(p.relative_to(top))))
    picked: list[Path] = []
    depth = 0
    while len(picked) < n and any(depth < len(g) for g in groups.values()):
        for key in sorted(groups, key=_digest):  # hashed: n < folders still spans them
            if depth < len(groups[key]) and len(picked) < n:
                picked.append(groups[key][depth])
        depth += 1
    return sorted(picked)


def _digest(text: str) -> str:
    return hashlib.sha1(text.encode()).hexdigest()


def fetch_librecad(dest: Path) -> list[Path]:
    """LibreCAD's parts library: DXF files."""
    root = extract(fetch_deb("librecad-data", dest / "debs"), dest / "pkg" / "librecad-data")
    return files_under(root / LIBRECAD_DIR, ".dxf")


def fetch_tango(dest: Path) -> list[Path]:
    """Tango's scalable icons: a varied pick of TANGO_ICONS SVG files (aliases skipped)."""
    root = extract(fetch_deb("tango-icon-theme", dest / "debs"), dest / "pkg" / "tango-icon-theme")
    return varied_sample(files_under(root / TANGO_DIR, ".svg"), root / TANGO_DIR, TANGO_ICONS)


def fetch_breeze(dest: Path) -> list[Path]:
    """Breeze's icons with a ``<style>`` sheet: a varied pick of BREEZE_ICONS SVG files."""
    deb = fetch_deb("breeze-icon-theme", dest / "debs")
    root = extract(deb, dest / "pkg" / "breeze-icon-theme", [f"./{BREEZE_DIR}/*.svg"])
    top = root / BREEZE_DIR
    sheets = [f for f in files_under(top, ".svg") if b"<style" in f.read_bytes()]
    return varied_sample(sheets, top, BREEZE_ICONS)


def fetch_inkscape(dest: Path) -> list[Path]:
    """Inkscape's example drawings (plain .svg only)."""
    deb = fetch_deb("inkscape", dest / "debs")
    root = extract(deb, dest / "pkg" / "inkscape", [f"./{INKSCAPE_DIR}/*.svg"])
    return files_under(root / INKSCAPE_DIR, ".svg")


def fetch_openscad_examples(dest: Path) -> list[Path]:
    """The DXF files of OpenSCAD's examples, from the package (no openscad binary needed)."""
    deb = fetch_deb("openscad", dest / "debs")
    root = extract(deb, dest / "pkg" / "openscad", [f"./{OPENSCAD_DIR}/*/*.dxf"])
    return files_under(root / OPENSCAD_DIR, ".dxf")


def fetch_openscad(dest: Path) -> list[Path]:
    """OpenSCAD's examples exported to DXF with the installed ``openscad`` (2D ones only)."""
    exe = shutil.which("openscad")
    if exe is None:
        log("openscad is not on PATH: OpenSCAD examples skipped")
        return []
    examples = Path("/usr/share/openscad/examples")
    out = dest / "openscad"
    out.mkdir(parents=True, exist_ok=True)
    for scad in sorted(examples.rglob("*.scad")):
        dxf = out / f"{scad.parent.name}-{scad.stem}.dxf"
        failed = dxf.with_suffix(".not2d")
        if dxf.exists() or failed.exists():
            continue
        try:
            _run([exe, "-o", str(dxf), str(scad)], timeout=120)
        except FetchError:
            failed.write_text("not a 2D example\n")  # 3D examples cannot be DXF
    return files_under(out, ".dxf")


def _missing_libs(exe: Path, libdirs: list[Path]) -> list[str]:
    env = dict(os.environ, LD_LIBRARY_PATH=os.pathsep.join(map(str, libdirs)))
    proc = subprocess.run(["ldd", str(exe)], capture_output=True, text=True, env=env, check=False)
    return [line.split()[0] for line in proc.stdout.splitlines() if "not found" in line]


def fetch_rs274(dest: Path) -> dict[str, object]:
    """LinuxCNC's rs274 with the libraries it needs; return its manifest entry."""
    root = dest / "pkg" / "linuxcnc"
    extract(fetch_deb("linuxcnc-uspace", dest / "debs"), root)
    libdirs = [root / "usr/lib", root / "usr/lib/x86_64-linux-gnu"]
    exe = root / RS274
    for soname in _missing_libs(exe, libdirs):
        pkg = next((p for prefix, p in RS274_LIBS.items() if soname.startswith(prefix)), None)
        if pkg is None:
            raise FetchError(f"rs274 needs {soname}, which no known package provides")
        extract(fetch_deb(pkg, dest / "debs"), dest / "pkg" / pkg)
        for sub in ("usr/lib", "usr/lib/x86_64-linux-gnu"):
            if dest / "pkg" / pkg / sub not in libdirs:
                libdirs.append(dest / "pkg" / pkg / sub)
    still = _missing_libs(exe, libdirs)
    if still:
        raise FetchError(f"rs274 still lacks {', '.join(still)}")
    table = dest / "rs274-tool.tbl"
    table.write_text("T1 P1 D3.0 Z0 ;corpus tool\n")
    return {
        "exe": _rel(exe, dest),
        "ld_library_path": [_rel(d, dest) for d in libdirs if d.is_dir()],
        "tool_table": _rel(table, dest),
    }


def _rel(path: Path, dest: Path) -> str:
    """PATH relative to DEST: the manifest stays right when the checkout moves."""
    return str(path.relative_to(dest))


def build_manifest(dest: Path) -> dict[str, object]:
    """Fetch every source that can be had; return the manifest (missing sources noted)."""
    notes: list[str] = []
    pools: dict[str, list[tuple[Path, list[Path]]]] = {"dxf": [], "svg": []}
    sources = [  # a source's share of the sample left unused goes to the sources after it
        ("dxf", fetch_openscad_examples),
        ("dxf", fetch_librecad),
        ("svg", fetch_tango),
        ("svg", fetch_breeze),
        ("svg", fetch_inkscape),
        ("dxf", fetch_openscad),
    ]
    for kind, fetch in sources:
        try:
            files = fetch(dest)
        except FetchError as exc:
            notes.append(f"{fetch.__name__}: {exc}")
            log(f"skipped: {exc}")
            continue
        if files:
            top = Path(os.path.commonpath([f.parent for f in files]))
            pools[kind].append((top, files))
    manifest: dict[str, object] = {"version": MANIFEST_VERSION, "notes": notes}
    for kind, pool in pools.items():
        full = [_rel(f, dest) for _, files in pool for f in files]
        sample: list[Path] = []
        for i, (top, files) in enumerate(pool):
            share = (SAMPLE_SIZE[kind] - len(sample)) // (
                len(pool) - i
            )  # an equal share per source
            light = [f for f in files if f.name not in HEAVY]
            sample += varied_sample(light, top, share)
        manifest[kind] = {"full": full, "sample": [_rel(f, dest) for f in sample]}
    try:
        manifest["rs274"] = fetch_rs274(dest)
    except FetchError as exc:
        notes.append(f"rs274: {exc}")
        log(f"rs274 skipped: {exc}")
    return manifest


def main(argv: list[str] | None = None) -> int:
    """Fetch what can be had into DEST and write its manifest; always exit 0."""
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--dest", type=Path, default=DEFAULT_DEST)
    parser.add_argument("--refresh", action="store_true", help="rebuild the manifest")
    args = parser.parse_args(argv)
    if os.environ.get(OFF_SWITCH) == "off":
        log(f"{OFF_SWITCH}=off: nothing fetched; the corpus tests skip")
        return 0
    dest: Path = args.dest.resolve()
    path = dest / MANIFEST
    if path.exists() and not args.refresh:
        cached = json.loads(path.read_text())
        notes = cached.get("notes", [])
        if cached.get("version") != MANIFEST_VERSION:
            log(f"{path} lists an older set of sources: rebuilding it")
        elif not notes:
            log(f"cached: {path} (--refresh to rebuild)")
            return 0
        else:
            log(f"retrying what failed last time: {'; '.join(notes)}")
    try:
        _apt_ready()
    except FetchError as exc:
        log(f"corpus not fetched: {exc}; the corpus tests will skip")
        return 0
    dest.mkdir(parents=True, exist_ok=True)
    manifest = build_manifest(dest)
    path.write_text(json.dumps(manifest, indent=1) + "\n")
    counts = {k: len(v["full"]) for k, v in manifest.items() if isinstance(v, dict) and "full" in v}
    log(f"wrote {path}: {counts} files, rs274 {'ready' if 'rs274' in manifest else 'missing'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
