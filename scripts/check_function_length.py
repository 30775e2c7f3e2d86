#!/usr/bin/env python3
"""Checks that no library function is longer than the limit (issue 19: about 80 lines).

A function's length runs from the line where its body's brace opens to the line where it closes,
lambdas and local classes included. Library code is every .cpp/.hpp under the library folders
(core, mesh, solvers, placement, fitting, probes, calibration, studies, io) and app/; tests,
benchmarks and fuzz targets are not library code. Comments, string and character literals are
blanked before the braces are counted, so a brace in a message does not count.

Prints each function over the limit with its file, first line and length; exits 1 if there is
one, 0 otherwise.
Usage: scripts/check_function_length.py [PROJECT_DIR] [--limit N]
"""
import argparse
import pathlib
import re
import sys

FOLDERS = ("core", "mesh", "solvers", "placement", "fitting", "probes", "calibration", "studies",
           "io", "app")
NOT_A_FUNCTION = re.compile(r"^(template\s*<[^{]*>\s*)?(namespace|struct|class|enum|union)\b")


def blanked(text):
    """The source with comments and literals replaced by blanks, line breaks kept."""
    keep_lines = lambda m: "\n" * m.group(0).count("\n")
    text = re.sub(r"//[^\n]*", "", text)
    text = re.sub(r"/\*.*?\*/", keep_lines, text, flags=re.S)
    text = re.sub(r'R"([^(\s]*)\(.*?\)\1"', lambda m: '""' + keep_lines(m), text, flags=re.S)
    text = re.sub(r'"(\\.|[^"\\\n])*"', '""', text)
    return re.sub(r"'(\\.|[^'\\\n])*'", "''", text)


def functions(text):
    """(first line, length, head) of each outermost function body in blanked source."""
    found, stack, line = [], [], 1
    for i, ch in enumerate(text):
        if ch == "\n":
            line += 1
        elif ch == "{":
            start = max(text.rfind(";", 0, i), text.rfind("}", 0, i), text.rfind("{", 0, i))
            head = " ".join(text[start + 1:i].split())
            is_function = ")" in head and not NOT_A_FUNCTION.match(head) and not head.endswith("=")
            stack.append((line, is_function, head))
        elif ch == "}" and stack:
            first, is_function, head = stack.pop()
            if is_function and not any(f for _, f, _ in stack):
                found.append((first, line - first + 1, head))
    return found


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("root", nargs="?", default=pathlib.Path(__file__).resolve().parent.parent)
    parser.add_argument("--limit", type=int, default=80)
    args = parser.parse_args()
    root = pathlib.Path(args.root)
    files = sorted(p for folder in FOLDERS for pattern in ("*.cpp", "*.hpp")
                   for p in (root / folder).rglob(pattern))
    over = []
    for path in files:
        for first, length, head in functions(blanked(path.read_text(encoding="utf-8"))):
            if length > args.limit:
                over.append((length, path.relative_to(root), first, head))
    for length, path, first, head in sorted(over, reverse=True):
        print(f"{path}:{first}: {length} lines: {head[-90:]}", file=sys.stderr)
    if over:
        print(f"check_function_length: {len(over)} functions over {args.limit} lines; split them "
              "into named steps", file=sys.stderr)
        return 1
    print(f"check_function_length: {len(files)} files, no function over {args.limit} lines")
    return 0


if __name__ == "__main__":
    sys.exit(main())
