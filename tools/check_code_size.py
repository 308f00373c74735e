#!/usr/bin/env python3
"""No source file over MAX_FILE_LINES lines and no function over MAX_FUNCTION_LINES lines in
src/, sensors/ and display/: a file is one concept, a function a list of named steps.

Functions are found by brace depth (namespace and extern "C" braces not counted; a brace
block at depth 0 whose opening line names a class, struct, enum or union is a type, and its
inline members are not measured). Comments and string literals are ignored.

Usage: check_code_size.py [ROOT]; exit 0 when within the limits, 1 listing every excess.
"""
import os
import re
import sys

import tree_check

MAX_FILE_LINES = 800
MAX_FUNCTION_LINES = 150
FOLDERS = ("src", "sensors", "display")
SOURCE_SUFFIXES = (".h", ".hpp", ".cpp", ".cc")
TYPE_OPENING = re.compile(r'\b(class|struct|enum|union)\b[^()]*$')


def code_of(line, in_block_comment):
    """The line without comments and string contents; whether a /* */ comment is still open."""
    out, i = [], 0
    while i < len(line):
        if in_block_comment:
            end = line.find("*/", i)
            if end < 0:
                return "".join(out), True
            i, in_block_comment = end + 2, False
        elif line.startswith("//", i):
            break
        elif line.startswith("/*", i):
            in_block_comment, i = True, i + 2
        elif line[i] in "\"'":
            quote, i = line[i], i + 1
            while i < len(line) and line[i] != quote:
                i += 2 if line[i] == "\\" else 1
            out.append(quote * 2)
            i += 1
        else:
            out.append(line[i])
            i += 1
    return "".join(out), in_block_comment


def long_functions(path):
    """(first line, length) of every function body longer than MAX_FUNCTION_LINES."""
    with open(path, encoding="utf-8", errors="replace") as f:
        lines = f.read().split("\n")
    found, depth, start, is_type, in_comment, opening = [], 0, None, False, False, ""
    for number, raw in enumerate(lines, 1):
        code, in_comment = code_of(raw, in_comment)
        if re.match(r'\s*(namespace\b[^;]*|extern\s*""\s*)\{', code):
            continue
        if re.match(r'\s*\}\s*$', code) and depth == 0:
            continue  # a namespace's closing brace
        for ch in code:
            if ch == "{":
                if depth == 0:
                    start = number
                    head = (opening + " " + code[:code.index("{")]).split(")")[-1]
                    is_type = bool(TYPE_OPENING.search(head)) and "(" not in code[:code.index("{")]
                depth += 1
            elif ch == "}":
                depth -= 1
                if depth == 0 and start is not None:
                    if not is_type and number - start + 1 > MAX_FUNCTION_LINES:
                        found.append((start, number - start + 1))
                    start = None
        if code.strip():
            opening = code if depth == 0 else opening
    return found


def violations(root):
    found = []
    for folder in FOLDERS:
        for dirpath, _, files in os.walk(os.path.join(root, folder)):
            for name in sorted(files):
                if not name.endswith(SOURCE_SUFFIXES):
                    continue
                path = os.path.join(dirpath, name)
                rel = os.path.relpath(path, root)
                with open(path, encoding="utf-8", errors="replace") as f:
                    count = sum(1 for _ in f)
                if count > MAX_FILE_LINES:
                    found.append("%s: %d lines (at most %d a file)" % (rel, count, MAX_FILE_LINES))
                for line, length in long_functions(path):
                    found.append("%s:%d: a function of %d lines (at most %d)" % (rel, line, length, MAX_FUNCTION_LINES))
    return found


def main():
    return tree_check.main(violations, "code size: %d excess(es) (see tools/check_code_size.py)",
                           "code size: every file in %s within %d lines, every function within %d" %
                           ("/, ".join(FOLDERS) + "/", MAX_FILE_LINES, MAX_FUNCTION_LINES))


if __name__ == "__main__":
    sys.exit(main())
