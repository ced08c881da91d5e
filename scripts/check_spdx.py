#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Fails when a source file of the repository lacks the licence's SPDX line (docs/licences.md).

A source file is a C++ file (.cpp, .hpp), a Python, shell or CMake script, a CMakeLists.txt, or
any file that starts with a shebang. The line `SPDX-License-Identifier: GPL-3.0-or-later` must
be in its first three lines (after a shebang or a module docstring's opening is fine).
Build folders (any folder with a CMakeCache.txt), results/, caches and hidden folders other
than .ci are not looked into.

    python3 scripts/check_spdx.py [ROOT]     # exit 0: every file has it; 1: lists those that do not
"""
import pathlib
import sys

LICENCE_LINE = "SPDX-License-Identifier: GPL-3.0-or-later"
SOURCE_SUFFIXES = {".cpp", ".hpp", ".py", ".sh", ".cmake"}
SKIPPED_FOLDERS = {"results", "__pycache__"}
LINES_LOOKED_AT = 3


def is_source(path: pathlib.Path) -> bool:
    if path.suffix in SOURCE_SUFFIXES or path.name == "CMakeLists.txt":
        return True
    try:
        with path.open("rb") as stream:
            return stream.read(2) == b"#!"
    except OSError:
        return False


def source_files(root: pathlib.Path):
    """Every source file below root, in sorted order, outside build, result and hidden folders."""
    for entry in sorted(root.iterdir()):
        if entry.is_dir():
            hidden = entry.name.startswith(".") and entry.name != ".ci"
            if hidden or entry.name in SKIPPED_FOLDERS or (entry / "CMakeCache.txt").exists():
                continue
            yield from source_files(entry)
        elif entry.is_file() and is_source(entry):
            yield entry


def carries_licence(path: pathlib.Path) -> bool:
    with path.open(encoding="utf-8", errors="replace") as stream:
        head = [stream.readline() for _ in range(LINES_LOOKED_AT)]
    return any(LICENCE_LINE in line for line in head)


def files_without_licence(root: pathlib.Path):
    return [path for path in source_files(root) if not carries_licence(path)]


def main(argv) -> int:
    root = pathlib.Path(argv[1] if len(argv) > 1 else pathlib.Path(__file__).resolve().parent.parent)
    missing = files_without_licence(root)
    for path in missing:
        print(f"{path.relative_to(root)}: no '{LICENCE_LINE}' in its first {LINES_LOOKED_AT} lines")
    if missing:
        print(f"check_spdx: {len(missing)} source file(s) without the licence line (docs/licences.md)")
        return 1
    print(f"check_spdx: {sum(1 for _ in source_files(root))} source files, each with the licence line")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
