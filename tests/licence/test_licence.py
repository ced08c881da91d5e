# SPDX-License-Identifier: GPL-3.0-or-later
"""The licence's checks (docs/licences.md): every source file carries the SPDX line, the check
finds a file that lacks it, and LICENSE, CITATION.cff and the CMake project agree."""
import pathlib
import re
import sys

REPOSITORY = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPOSITORY / "scripts"))
import check_spdx  # noqa: E402


def test_every_source_file_of_the_repository_carries_the_licence_line():
    missing = check_spdx.files_without_licence(REPOSITORY)
    assert [str(p.relative_to(REPOSITORY)) for p in missing] == []


def test_the_check_finds_the_files_without_the_line_and_skips_build_and_results(tmp_path):
    (tmp_path / "good.cpp").write_text("// " + check_spdx.LICENCE_LINE + "\nint x;\n")
    (tmp_path / "bad.hpp").write_text("#pragma once\n")
    (tmp_path / "tool").write_text("#!/bin/sh\necho no licence\n")
    (tmp_path / "late.py").write_text('"""a"""\n\n\n# ' + check_spdx.LICENCE_LINE + "\n")
    (tmp_path / "notes.md").write_text("not a source file\n")
    build = tmp_path / "build-fuzz"
    build.mkdir()
    (build / "CMakeCache.txt").write_text("")
    (build / "generated.cpp").write_text("int y;\n")
    (tmp_path / "results").mkdir()
    (tmp_path / "results" / "probe.py").write_text("x = 1\n")
    found = sorted(p.name for p in check_spdx.files_without_licence(tmp_path))
    assert found == ["bad.hpp", "late.py", "tool"]
    assert check_spdx.main(["check_spdx", str(tmp_path)]) == 1


def top_level_value(text, key):
    match = re.search(rf"^{key}:\s*\"?([^\"\n]+)\"?\s*$", text, re.MULTILINE)
    assert match, f"CITATION.cff has no top-level '{key}'"
    return match.group(1).strip()


def test_licence_citation_and_project_version_agree():
    licence = (REPOSITORY / "LICENSE").read_text()
    assert "GNU GENERAL PUBLIC LICENSE" in licence.splitlines()[0]
    assert "Version 3, 29 June 2007" in licence.splitlines()[1]
    citation = (REPOSITORY / "CITATION.cff").read_text()
    assert top_level_value(citation, "cff-version") == "1.2.0"
    assert top_level_value(citation, "license") == "GPL-3.0-or-later"
    project = re.search(r"project\(arlequin VERSION (\S+)", (REPOSITORY / "CMakeLists.txt").read_text())
    assert top_level_value(citation, "version") == project.group(1)
