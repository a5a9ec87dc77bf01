"""The documents a clone reads: every relative link of the README and of docs/*.md points at a file of the
repository (and at a heading of it when it names one), and the formulas of docs/model.md and docs/parameters.md are
well formed for GitHub's math (delimiters paired, braces and \\left/\\right balanced, no pipe inside a table's math)."""
from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
LINK = re.compile(r"(?<!\!)\[[^\]]*\]\(([^)\s]+)\)|\!\[[^\]]*\]\(([^)\s]+)\)")


def _prose(text: str) -> str:
    """The text without fenced code blocks and inline code spans (links and math inside them are not read)."""
    text = re.sub(r"^```.*?^```", "", text, flags=re.M | re.S)
    return re.sub(r"`[^`\n]*`", "``", text)


def slug(heading: str) -> str:
    """GitHub's anchor of a heading: lower case, punctuation dropped (word characters, spaces, hyphens kept),
    spaces as hyphens."""
    h = re.sub(r"`", "", heading.strip().lower())
    return re.sub(r"[^\w\- ]", "", h).replace(" ", "-")


def anchors(path: Path) -> set[str]:
    seen: dict[str, int] = {}
    out = set()
    for line in _prose_lines(path):
        m = re.match(r"^#{1,6} (.*)$", line)
        if m:
            s = slug(m.group(1))
            n = seen.get(s, 0)
            seen[s] = n + 1
            out.add(s if n == 0 else f"{s}-{n}")
    return out


def _prose_lines(path: Path) -> list[str]:
    return re.sub(r"^```.*?^```", "", path.read_text(encoding="utf-8"), flags=re.M | re.S).splitlines()


def test_slugs_are_githubs():
    assert slug("## 10. Scenes: the DPGT on the source's rig".lstrip("# ")) == "10-scenes-the-dpgt-on-the-sources-rig"
    assert slug("`errors`") == "errors" and slug("3.1 HHT-α") == "31-hht-α"


@pytest.mark.parametrize("doc", DOCS, ids=lambda p: str(p.relative_to(ROOT)))
def test_relative_links_point_at_files_and_headings_of_the_repository(doc):
    bad = []
    for m in LINK.finditer(_prose(doc.read_text(encoding="utf-8"))):
        target = m.group(1) or m.group(2)
        if re.match(r"[a-z]+:", target):             # http(s), mailto: not this repository's
            continue
        path, _, anchor = target.partition("#")
        file = (doc.parent / path).resolve() if path else doc
        if not file.exists() or ROOT not in file.parents:
            bad.append(f"{target}: no such file in the repository")
        elif anchor and file.suffix == ".md" and anchor not in anchors(file):
            bad.append(f"{target}: no heading with that anchor in {file.relative_to(ROOT)}")
    assert not bad, f"{doc.relative_to(ROOT)}: " + "; ".join(bad)


def _math_spans(text: str) -> list[tuple[str, bool]]:
    """(math, in a table row) of every $$...$$ block and $...$ span of the prose."""
    spans = []
    prose = _prose(text)
    for block in re.findall(r"\$\$(.*?)\$\$", prose, flags=re.S):
        spans.append((block, None))
    # a display block stands alone: $$ opens a line and closes one
    for m in re.finditer(r"\$\$(.*?)\$\$", prose, flags=re.S):
        start, end = m.start(), m.end()
        assert start == 0 or prose[start - 1] == "\n", f"$$ not at the start of a line: {m.group(0)[:60]}"
        assert end == len(prose) or prose[end] == "\n", f"text after a closing $$: {m.group(0)[-60:]}"
    prose = re.sub(r"\$\$.*?\$\$", "", prose, flags=re.S)
    for line in prose.splitlines():
        parts = line.split("$")
        assert len(parts) % 2 == 1, f"unpaired $ in: {line[:100]}"
        spans += [(p, line.startswith("|")) for p in parts[1::2]]
    return spans


@pytest.mark.parametrize("name", ["model.md", "parameters.md"])
def test_formulas_are_well_formed(name):
    spans = _math_spans((ROOT / "docs" / name).read_text(encoding="utf-8"))
    if name == "model.md":
        assert len(spans) > 200
    for math, in_table in spans:
        assert in_table is None or (math.strip() and math == math.strip()), f"space inside $ delimiters: ${math}$"
        body = re.sub(r"\\[{}]", "", math)
        depth = 0
        for ch in body:
            depth += {"{": 1, "}": -1}.get(ch, 0)
            assert depth >= 0, f"unbalanced braces: {math}"
        assert depth == 0, f"unbalanced braces: {math}"
        assert math.count(r"\left") == math.count(r"\right"), f"\\left without \\right: {math}"
        assert not (in_table and "|" in math), f"a pipe inside a table's math breaks the table: {math}"


def test_the_model_document_names_only_test_files_that_exist():
    text = (ROOT / "docs" / "model.md").read_text(encoding="utf-8")
    named = set(re.findall(r"`(tests/[\w/]+\.py)`", text))
    assert len(named) > 30
    assert not [t for t in named if not (ROOT / t).exists()]
