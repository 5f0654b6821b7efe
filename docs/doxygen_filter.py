#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Doxygen's input filter for include/trivcon/*.h (docs/Doxyfile): the headers document themselves in plain //
comments; this turns them into Doxygen's on the fly, leaving the headers as they are.

- the file's leading comment block becomes the file's documentation (@file);
- a whole-line // comment becomes ///, documenting the declaration that follows;
- a // comment after code on the same line becomes ///<, documenting that member;
- in comment text, characters Doxygen would take as commands or HTML (\\ @ < > & # %) are escaped, so the text
  reads as written.
Prints the filtered file to stdout, line for line but for one line added at the top."""

import re
import sys

SPECIAL = re.compile(r"([\\@<>&#%$])")


def escape(text):
    # Outside `code spans` escape Doxygen's command and HTML characters; inside them Markdown keeps text literal.
    parts = text.split("`")
    for i in range(0, len(parts), 2):
        parts[i] = SPECIAL.sub(r"\\\1", parts[i])
    if len(parts) % 2 == 0:  # an unpaired backtick: take it literally
        return SPECIAL.sub(r"\\\1", text).replace("`", "\\`")
    return "`".join(parts)


def code_comment_split(line):
    """(code, comment) of a line: the position of a // outside string and character literals, or None."""
    quote = None
    i = 0
    while i < len(line):
        c = line[i]
        if quote:
            if c == "\\":
                i += 2
                continue
            if c == quote:
                quote = None
        elif c in "\"'":
            quote = c
        elif line.startswith("//", i):
            return line[:i], line[i + 2:]
        i += 1
    return line, None


def main():
    lines = open(sys.argv[1], encoding="utf-8").read().split("\n")
    out = []
    leading = True
    for n, line in enumerate(lines):
        stripped = line.lstrip()
        if leading and stripped.startswith("//"):
            # The file's own documentation: @file on a line of its own before the first line (its text is then
            # the brief); the only place where the output gains a line.
            out.append(("/// @file\n" if n == 0 else "") + "///" + escape(stripped[2:]))
            continue
        leading = False
        if stripped.startswith("//"):
            text = stripped[2:]
            if text.startswith("/") or text.startswith("!"):
                out.append(line)  # already a Doxygen comment
            else:
                out.append(line[: len(line) - len(stripped)] + "///" + escape(text))
            continue
        code, comment = code_comment_split(line)
        if comment is None or not code.strip():
            out.append(line)
        elif comment.startswith("/<") or comment.startswith("!<"):
            out.append(line)
        else:
            out.append(code + "///<" + escape(comment))
    sys.stdout.write("\n".join(out))


if __name__ == "__main__":
    main()
