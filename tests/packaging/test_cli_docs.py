# SPDX-License-Identifier: MIT
"""The test Package.CliDocs (tests/CMakeLists.txt): the man page and the bash completion the build generated
(scripts/cli_help.py), and the Markdown reference, against the program's help read here independently.

    test_cli_docs.py --program BUILD/trivcon --man BUILD/.../trivcon.1 --completion BUILD/.../trivcon
                     --cli-help scripts/cli_help.py --commands-header apps/commands.h

Checks that every subcommand and every long option of `trivcon CMD --help` is in the man page's subsection of
that command, in the Markdown page's section of it and in the completion's answer to `trivcon CMD --<TAB>`;
that the completion offers every subcommand, and the choices of an option with a fixed set of values after it;
that the man page renders without a groff warning and lists every exit status of apps/commands.h; and that the
generator refuses a program it cannot read, with a message."""

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
import unittest

ARGS = None


def run(*cmd, check=True):
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if check and p.returncode != 0:
        raise AssertionError(f"{' '.join(cmd)} exited {p.returncode}: {p.stderr}")
    return p


def help_of(*args):
    return run(ARGS.program, *args, "--help").stdout


def commands():
    """The subcommands: the lines of the top-level help's 'Subcommands:' section."""
    text = help_of()
    block = text.split("Subcommands:\n", 1)[1].split("\n\n", 1)[0]
    return [line.split()[0] for line in block.split("\n") if line.startswith("  ")]


def long_options(command):
    """The long options of a command: the --names in the first word of its help's option lines."""
    names = []
    for line in help_of(command).split("\n"):
        if line.startswith("  -"):
            names += [n for n in line.split()[0].split(",") if n.startswith("--")]
    return names


def choice_options(command):
    """Options with a fixed set of values: {--name: [values]} from 'NAME TEXT:{a,b}'."""
    out = {}
    for line in help_of(command).split("\n"):
        m = re.match(r"^  (\S+) \S*:\{([^}]*)\}", line)
        if m:
            for n in m.group(1).split(","):
                out[n] = m.group(2).split(",")
    return out


def complete(*words):
    """The completion's answer for the command line `words` (the last one being completed)."""
    script = (f"source '{ARGS.completion}'; COMP_WORDS=({' '.join(repr(w) for w in words)}); "
              f"COMP_CWORD={len(words) - 1}; _trivcon; printf '%s\\n' \"${{COMPREPLY[@]}}\"")
    return run("bash", "-c", script).stdout.split()


def man_source():
    with open(ARGS.man, encoding="utf-8") as f:
        return f.read()


def man_subsection(command):
    """The man page's subsection of a command, its roff hyphens plain."""
    parts = re.split(r"^\.SS ", man_source(), flags=re.M)
    found = [p for p in parts[1:] if p.startswith(f'"trivcon {command} ')]
    if len(found) != 1:
        raise AssertionError(f"the man page has {len(found)} subsections for {command}")
    return re.split(r"^\.SH ", found[0], flags=re.M)[0].replace("\\-", "-")


class ManPage(unittest.TestCase):
    def test_renders_without_warnings(self):
        if not shutil.which("groff"):
            self.skipTest("no groff (Debian: groff-base; scripts/deps.sh installs it)")
        p = run("groff", "-man", "-Tutf8", "-ww", "-z", ARGS.man)
        self.assertEqual(p.stderr, "")

    def test_every_command_and_option(self):
        for command in commands():
            section = man_subsection(command)
            for option in long_options(command):
                self.assertRegex(section, rf"\.BI? \"(-\w,)?{re.escape(option)}[ \"]", f"{command} {option}")

    def test_sections_and_version(self):
        source = man_source()
        version = run(ARGS.program, "--version").stdout.split()[1]
        self.assertRegex(source, rf'(?m)^\.TH TRIVCON 1 "[^"]*" "trivcon {re.escape(version)}"')
        self.assertEqual(re.findall(r"(?m)^\.SH (.+)$", source),
                         ["NAME", "SYNOPSIS", "DESCRIPTION", "OPTIONS", "COMMANDS", "EXIT STATUS", "SEE ALSO"])
        # The exit statuses once, not again in every command's subsection (CLI11 copies a footer set too early).
        self.assertEqual(re.findall(r"(?m)^\.I (.+)$", source.split(".SH COMMANDS", 1)[1].split(".SH ", 1)[0]),
                         [t for c in commands() for t in ("Positionals", "Options")])

    def test_every_exit_status(self):
        with open(ARGS.commands_header, encoding="utf-8") as f:
            enum = f.read().split("enum ExitStatus", 1)[1].split("};", 1)[0]
        codes = sorted(int(c) for c in re.findall(r"= (\d+)", enum))
        self.assertGreaterEqual(len(codes), 5)
        statuses = man_source().split(".SH EXIT STATUS", 1)[1].split(".SH ", 1)[0]
        self.assertEqual(sorted(int(c) for c in re.findall(r"(?m)^\.B (\d+)$", statuses)), codes)


class Completion(unittest.TestCase):
    def test_subcommands(self):
        reply = complete("trivcon", "")
        for command in commands():
            self.assertIn(command, reply)
        self.assertEqual(complete("trivcon", "so"), ["solve"])

    def test_every_long_option(self):
        for command in commands():
            self.assertEqual(sorted(set(complete("trivcon", command, "--"))), sorted(set(long_options(command))), command)

    def test_choices(self):
        seen = 0
        for command in commands():
            for option, values in choice_options(command).items():
                self.assertEqual(sorted(complete("trivcon", command, option, "")), sorted(values), f"{command} {option}")
                seen += 1
        self.assertGreater(seen, 0, "no option with a fixed set of values in the help")

    def test_options_after_other_words(self):
        # The subcommand is found before other words (here the mesh).
        self.assertIn("--json", complete("trivcon", "info", "mesh.obj", "--j"))


class Markdown(unittest.TestCase):
    def test_every_command_and_option(self):
        with tempfile.TemporaryDirectory() as folder:
            run(sys.executable, ARGS.cli_help, "--program", ARGS.program, "--format", "markdown", "--out", folder)
            self.assertEqual(os.listdir(folder), ["cli.md"])
            with open(os.path.join(folder, "cli.md"), encoding="utf-8") as f:
                page = f.read()
        sections = dict(re.findall(r"(?ms)^## trivcon (\S+)\n(.*?)(?=^## |\Z)", page))
        self.assertEqual(sorted(sections), sorted(commands()))
        for command in commands():
            for option in long_options(command):
                self.assertRegex(sections[command], rf"\| `(-\w,)?{re.escape(option)}[ `]", f"{command} {option}")


class Generator(unittest.TestCase):
    def test_refuses_what_it_cannot_read(self):
        with tempfile.TemporaryDirectory() as folder:
            out = os.path.join(folder, "trivcon.1")
            p = run(sys.executable, ARGS.cli_help, "--program", os.path.join(folder, "missing"), "--format", "man",
                    "--out", out, check=False)
            self.assertEqual(p.returncode, 1)
            self.assertIn("cannot run", p.stderr)
            # A program whose help is not CLI11's.
            other = os.path.join(folder, "other")
            with open(other, "w") as f:
                f.write("#!/bin/sh\necho 'some other program'\n")
            os.chmod(other, 0o755)
            p = run(sys.executable, ARGS.cli_help, "--program", other, "--format", "man", "--out", out, check=False)
            self.assertEqual(p.returncode, 1)
            self.assertIn("no 'Usage:' line", p.stderr)
            self.assertFalse(os.path.exists(out))


if __name__ == "__main__":
    parser = argparse.ArgumentParser()
    for name in ("--program", "--man", "--completion", "--cli-help", "--commands-header"):
        parser.add_argument(name, required=True)
    ARGS, rest = parser.parse_known_args()
    unittest.main(argv=[sys.argv[0], *rest])
