"""Writes the plugin C ABI reference (Markdown) from the public plugin headers: every C
declaration with the doc comment above it, grouped by the headers' section comments, and the hooks
of the C++ base class ambfplus::plugin::Plugin.

    python docs/hooks/plugin_abi.py [ROOT]     # prints the page's generated part
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

HEADERS = ("cpp/include/ambfplus/plugin/plugin.h", "cpp/include/ambfplus/plugin/api.h")
SECTION = re.compile(r"^/\*\s*-+\s*(.+?)\s*-+\s*\*/$")


def _comment_text(lines: list[str]) -> str:
    """The words of a doc comment (/** ... */ or ///), without its markers."""
    words = []
    for line in lines:
        line = line.strip()
        line = re.sub(r"^(/\*\*|/\*|///|\*/|\*)", "", line)
        line = re.sub(r"\*/$", "", line)
        words.append(line.strip())
    return " ".join(w for w in words if w)


def _clean(declaration: str) -> str:
    text = declaration.replace("AMBFPLUS_API ", "")
    return re.sub(r"[ \t]+\n", "\n", text).strip()


def declarations(path: Path):
    """Yields (section, doc, declaration) for the C part of a header: what lies inside its
    extern "C" block, plus its #define constants."""
    lines = path.read_text(encoding="utf-8").splitlines()
    in_c, section, doc = False, "", []
    i = 0
    while i < len(lines):
        raw = lines[i]
        line = raw.strip()
        if line.startswith('extern "C"'):
            in_c = True
        elif in_c and line == "}" and not doc:
            in_c = False  # plugin.h closes its extern "C" block with a bare brace
        elif SECTION.match(line):
            section, doc = SECTION.match(line).group(1), []
        elif line.startswith("/**") or line.startswith("///"):
            # A doc comment runs to its */ (block) or over consecutive /// lines.
            block = [raw]
            if line.startswith("/**"):
                while "*/" not in lines[i]:
                    i += 1
                    block.append(lines[i])
            else:
                while i + 1 < len(lines) and lines[i + 1].strip().startswith("///"):
                    i += 1
                    block.append(lines[i])
            doc = block
        elif line.startswith("#define"):
            # A macro's first line names it; its continuation lines are its body.
            name = line.rstrip("\\").rstrip()
            while lines[i].rstrip().endswith("\\"):
                i += 1
            if doc:
                yield section, _comment_text(doc), name
            doc = []
        elif in_c and line and not line.startswith(("#", "//", "/*", "*")):
            # A declaration: a struct or enum to its closing brace, anything else to its ';'.
            block = [raw]
            if line.endswith("{"):
                depth = line.count("{") - line.count("}")
                while depth > 0:
                    i += 1
                    block.append(lines[i])
                    depth += lines[i].count("{") - lines[i].count("}")
            else:
                while not lines[i].rstrip().endswith(";"):
                    i += 1
                    block.append(lines[i])
            yield section, _comment_text(doc), _clean("\n".join(block))
            doc = []
        elif not line:
            pass
        else:
            doc = []
        i += 1


def cpp_hooks(path: Path):
    """Yields (signature, doc) for the virtual hooks of ambfplus::plugin::Plugin."""
    text = path.read_text(encoding="utf-8")
    body = text[text.index("class Plugin {") :]
    body = body[: body.index("\n};")]
    doc: list[str] = []
    for line in body.splitlines():
        stripped = line.strip()
        if stripped.startswith("///"):
            doc.append(stripped)
        elif stripped.startswith("virtual") and "~" not in stripped:
            signature = re.sub(r"\s*\{.*$", "", stripped.replace("virtual ", ""))
            yield signature, _comment_text(doc)
            doc = []
        else:
            doc = []


def _flush(group: list[tuple[str, str]], out: list[str]) -> None:
    for doc, code in group:
        out.append(f"```c\n{code}\n```\n")
        if doc:
            out.append(doc + "\n")
    group.clear()


def render(root: Path) -> str:
    out = []
    for header in HEADERS:
        path = root / header
        out.append(f"## `{header.removeprefix('cpp/include/')}`\n")
        current = None
        group: list[tuple[str, str]] = []

        for section, doc, code in declarations(path):
            if section != current:
                _flush(group, out)
                if section:
                    out.append(f"### {section}\n")
                current = section
            # A declaration without a comment of its own shares the one above it.
            if not doc and group:
                prev_doc, prev_code = group[-1]
                group[-1] = (prev_doc, prev_code + "\n" + code)
            else:
                group.append((doc, code))
        _flush(group, out)
    out.append("## C++ hooks: `ambfplus::plugin::Plugin`\n")
    out.append("| hook | when it runs |\n|---|---|")
    for signature, doc in cpp_hooks(root / HEADERS[0]):
        out.append(f"| `{signature}` | {doc.replace('|', '&#124;')} |")
    return "\n".join(out) + "\n"


if __name__ == "__main__":
    sys.stdout.write(render(Path(sys.argv[1]) if len(sys.argv) > 1 else Path.cwd()))
