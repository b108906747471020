#!/usr/bin/env python3
"""The size rule of docs/ARCHITECTURE.md: no C++ source file over 800 lines and no function over
150 lines in the core and its front ends (src/, cli/, viewer/, python/; tests/, bench/, fuzz/ and
examples/ are exempt: a test file grows with the cases it checks).

A function is found by matching braces on the text with comments, strings and preprocessor lines
blanked out: a `{` opened outside any function whose header (the text since the previous `;`, `{`
or `}`) closes a parameter list -- `f(...) {`, `f(...) const noexcept {`, `[](...) -> T {`,
`X::X(...) : a(b) {` -- starts a function, and everything up to its matching `}` (nested lambdas,
local classes) counts as its lines, from the header's first line to the closing brace.

Usage: check_sizes.py [REPO_ROOT] [--max-file N] [--max-function N] [--list N]
Exit 0 when the tree follows the rule, 1 listing every file and function over it."""
import argparse
import os
import re
import sys

FOLDERS = ["src", "cli", "viewer", "python"]
EXTENSIONS = (".h", ".hpp", ".cpp", ".cc", ".cxx")
# After a parameter list's `)`, what may stand before a function body's `{`.
_TRAILER = re.compile(
    r"\)\s*(?:(?:const|noexcept|override|final|mutable|constexpr|volatile|&&|&)\s*|noexcept\s*\([^()]*\)\s*)*"
    r"(?:->\s*[\w:<>,\s*&\[\]]+)?\s*$"
)


def blank(text):
    """Comments, string and character literals and preprocessor lines replaced by spaces
    (newlines kept, so line numbers stay)."""
    out = []
    i, n = 0, len(text)
    line_start = True
    while i < n:
        c = text[i]
        if line_start and c == "#":
            # A preprocessor line, with its continuations.
            j = i
            while j < n and text[j] != "\n":
                if text[j] == "\\" and j + 1 < n and text[j + 1] == "\n":
                    j += 2
                    out.append(" \n")
                    continue
                out.append(" ")
                j += 1
            i = j
            continue
        if c == "\n":
            out.append(c)
            line_start = True
            i += 1
            continue
        if c in " \t":
            out.append(c)
            i += 1
            continue
        line_start = False
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c == "R" and text.startswith('R"', i) and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
            m = re.match(r'R"([^(\s]{0,16})\(', text[i:])
            if not m:
                out.append(c)
                i += 1
                continue
            end = text.find(")" + m.group(1) + '"', i + m.end())
            j = n if end < 0 else end + len(m.group(1)) + 2
            out.append('""' + re.sub(r"[^\n]", " ", text[i + 2 : j]))
            i = j
        elif c == '"' or (c == "'" and not (i > 0 and text[i - 1].isalnum())):
            # A literal (a digit separator 1'000 is not one).
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            j = min(j + 1, n)
            out.append(c + " " * (j - i - 2) + c if j - i >= 2 else c)
            i = j
        else:
            out.append(c)
            i += 1
    return "".join(out)


def functions(text):
    """(name, first line, last line) of each outermost function body in a C++ text."""
    code = blank(text)
    result = []
    stack = []  # per open brace: True when it is (inside) a function body
    header_start = 0
    for i, c in enumerate(code):
        if c == "{":
            inside = bool(stack) and stack[-1]
            if inside:
                stack.append(True)
            else:
                header = code[header_start:i]
                is_function = bool(_TRAILER.search(header)) or bool(
                    re.search(r"\)\s*:[^;]*\}\s*$", header)  # an initialiser list ending in a brace initialiser
                )
                if is_function and re.match(r"\s*(namespace|class|struct|union|enum)\b", header):
                    is_function = False
                if not is_function and re.search(r"\)\s*:[^;]*[\w>]\s*$", header):
                    # A member's brace initialiser in a constructor's initialiser list: the header
                    # goes on to the body's brace.
                    stack.append("init")
                    continue
                if is_function:
                    first = header_start + (len(header) - len(header.lstrip()))
                    name_match = re.search(r"([~\w:]+|\[[^\]]*\])\s*\(", header)
                    name = name_match.group(1) if name_match else "?"
                    stack.append(("function", name, code.count("\n", 0, first) + 1))
                else:
                    stack.append(False)
            header_start = i + 1
        elif c == "}":
            if stack:
                top = stack.pop()
                if isinstance(top, tuple):
                    result.append((top[1], top[2], code.count("\n", 0, i) + 1))
                if top == "init":
                    continue
            header_start = i + 1
        elif c == ";":
            header_start = i + 1
    return result


def sources(root):
    for folder in FOLDERS:
        base = os.path.join(root, folder)
        for dirpath, dirnames, filenames in os.walk(base):
            dirnames[:] = sorted(d for d in dirnames if not d.startswith(".") and d != "build")
            for f in sorted(filenames):
                if f.endswith(EXTENSIONS):
                    yield os.path.join(dirpath, f)


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("root", nargs="?", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
    ap.add_argument("--max-file", type=int, default=800)
    ap.add_argument("--max-function", type=int, default=150)
    ap.add_argument("--list", type=int, default=0, help="also print the N longest functions")
    args = ap.parse_args(argv)
    root = os.path.abspath(args.root)
    problems = []
    longest = []
    for path in sources(root):
        rel = os.path.relpath(path, root)
        with open(path, encoding="utf-8", errors="replace") as f:
            text = f.read()
        lines = text.count("\n") + (0 if text.endswith("\n") or not text else 1)
        if lines > args.max_file:
            problems.append(f"{rel}: {lines} lines (a source file may have at most {args.max_file})")
        for name, first, last in functions(text):
            length = last - first + 1
            longest.append((length, f"{rel}:{first} {name}"))
            if length > args.max_function:
                problems.append(
                    f"{rel}:{first}: function {name} is {length} lines (at most {args.max_function})"
                )
    if args.list:
        for length, where in sorted(longest, reverse=True)[: args.list]:
            print(f"{length:5d}  {where}")
    if problems:
        print("size check: %d problem(s)" % len(problems))
        for p in problems:
            print("  " + p)
        return 1
    print(f"size check: ok (no file over {args.max_file} lines, no function over {args.max_function})")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
