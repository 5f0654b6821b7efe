#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The command-line reference of `trivcon`, generated from the program's own help so that it never drifts.

    cli_help.py --program PATH/trivcon --format man|markdown|bash --out PATH

Runs `trivcon --help`, then `trivcon CMD --help` for every subcommand its "Subcommands:" section lists,
parses CLI11's layout (sections "Name:" at column 0, items indented by two spaces, descriptions from
column 30 or, after a long name, on the next line) and writes:

  man       one roff page (trivcon.1): NAME, SYNOPSIS, DESCRIPTION, OPTIONS, COMMANDS (a subsection per
            command with its arguments and options), EXIT STATUS (from the help's "Exit status:" section),
            SEE ALSO. --out is the file.
  markdown  a folder with one page, cli.md: the same content for a documentation site. --out is the folder.
  bash      a bash completion script: subcommands, each command's options, the choices of {a,b} options,
            file names elsewhere. --out is the file.

Python 3 standard library only. Exit status 0, or 1 with a message on stderr (program missing or failing,
help in an unexpected layout)."""

import argparse
import os
import re
import subprocess
import sys

COLUMN = 30  # CLI11's default column of descriptions


class HelpError(Exception):
    pass


def run_help(program, args):
    try:
        out = subprocess.run([program, *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, check=False)
    except OSError as e:
        raise HelpError(f"cannot run {program}: {e.strerror}")
    if out.returncode != 0:
        raise HelpError(f"`{' '.join([program, *args])}` exited with status {out.returncode}: {out.stderr.strip()}")
    return out.stdout


def split_item(line, next_line):
    """One item line of a section ("  NAME[ TYPE]   DESCRIPTION") -> (name, description on this line)."""
    body = line[2:]
    continued = next_line is not None and next_line.startswith(" " * COLUMN) and next_line[COLUMN:COLUMN + 1] not in ("", " ")
    if len(line) <= COLUMN:
        return body.strip(), ""
    head, tail = line[:COLUMN], line[COLUMN:]
    # A name of 28 characters or more is printed alone, its description on the next line. A shorter name is padded
    # to the column, so the column is preceded by a space; a long name continuing past the column with a single
    # space before it is told apart by its description following on the next line and by having no padding
    # (two spaces) inside.
    if head.endswith(" ") and not (continued and "  " not in body.strip()):
        return head.strip(), tail.strip()
    return body.strip(), ""


def parse_help(text):
    """CLI11's help -> {"description", "usage", "sections": [(title, [(name, description)])], "footer"}."""
    lines = text.rstrip("\n").split("\n")
    usage_at = next((i for i, l in enumerate(lines) if l.startswith("Usage: ")), None)
    if usage_at is None:
        raise HelpError("no 'Usage:' line in the help:\n" + text)
    description = " ".join(l.strip() for l in lines[:usage_at] if l.strip())
    usage = lines[usage_at][len("Usage: "):].strip()
    sections, footer = [], []
    current = None
    i = usage_at + 1
    while i < len(lines):
        line = lines[i]
        nxt = lines[i + 1] if i + 1 < len(lines) else None
        if not line.strip():
            current = None
        elif re.match(r"^[A-Za-z][A-Za-z ]*:$", line):
            current = (line[:-1], [])
            sections.append(current)
        elif current is not None and line.startswith("  ") and not line.startswith(" " * COLUMN):
            name, desc = split_item(line, nxt)
            current[1].append([name, desc])
        elif current is not None and line.startswith(" " * COLUMN) and current[1]:
            item = current[1][-1]
            item[1] = (item[1] + " " + line.strip()).strip()
        else:
            footer.append(line.strip())
            current = None
        i += 1
    return {"description": description, "usage": usage, "sections": sections, "footer": " ".join(footer)}


def program_usage(usage, program):
    """The usage line with the path the program was run by replaced by its name."""
    return re.sub(r"^\S*" + re.escape(os.path.basename(program)), "trivcon", usage)


def section(helpd, *titles):
    wanted = {t.lower() for t in titles}
    return next((items for title, items in helpd["sections"] if title.lower() in wanted), [])


def collect(program):
    top = parse_help(run_help(program, ["--help"]))
    version = run_help(program, ["--version"]).strip()
    match = re.fullmatch(r"trivcon (\S+)", version)
    if not match:
        raise HelpError(f"unexpected --version output: {version!r}")
    commands = []
    for name, desc in section(top, "Subcommands"):
        sub = parse_help(run_help(program, [name, "--help"]))
        sub["name"] = name
        sub["usage"] = program_usage(sub["usage"], program)
        sub["summary"] = desc
        commands.append(sub)
    if not commands:
        raise HelpError("the help lists no subcommands (no 'Subcommands:' section)")
    top["usage"] = program_usage(top["usage"], program)
    summary = re.sub(r"^trivcon:\s*", "", top["description"])  # "trivcon: what it does" -> "what it does"
    return {"version": match.group(1), "summary": summary, "top": top, "commands": commands}


# Options: their names and their choices.

def option_names(name):
    """'-s,--singularities TEXT ... Excludes: --auto' -> ['-s', '--singularities']."""
    return name.split(" ", 1)[0].split(",")


def option_choices(name):
    """The values of an option with a fixed set: '--up TEXT:{x,y,z}' -> ['x', 'y', 'z']; [] for others."""
    m = re.search(r":\{([^}]*)\}", name)
    return m.group(1).split(",") if m else []


# man

def roff(text):
    """Text for a roff line: backslashes, hyphens (as minus signs, so that options copy right), leading dots."""
    text = text.replace("\\", "\\e").replace("-", "\\-")
    return "\\&" + text if text.startswith((".", "'")) else text


def man_items(out, items):
    """A tagged paragraph per item: its name bold, what follows (type, constraints) italic."""
    for name, desc in items:
        first, _, rest = name.partition(" ")
        out += [".TP", f'.BI "{roff(first)} " "{roff(rest)}"' if rest else f'.B "{roff(first)}"', roff(desc)]


def exit_statuses(helpd):
    return section(helpd, "Exit status", "Exit statuses", "Exit codes")


def write_man(info, path):
    top, version, summary = info["top"], info["version"], info["summary"]
    out = [
        '.\\" SPDX-License-Identifier: MIT',
        '.\\" Generated by scripts/cli_help.py from `trivcon --help`: do not edit.',
        f'.TH TRIVCON 1 "" "trivcon {roff(version)}" "User Commands"',
        ".SH NAME",
        f"trivcon \\- {roff(summary)}",
        ".SH SYNOPSIS",
    ]
    for cmd in info["commands"]:
        out.append(f".B trivcon {roff(cmd['name'])}")
        for word in cmd["usage"].split()[2:]:  # "[OPTIONS]" and the positionals
            out.append(f".RI [ {roff(word[1:-1].lower())} ]" if word.startswith("[") else f".I {roff(word)}")
        out.append(".br")
    out += [".B trivcon \\-\\-help", ".br", ".B trivcon \\-\\-version"]
    out += [".SH DESCRIPTION", roff(summary[:1].upper() + summary[1:]) + ".", ".PP", "Commands:"]
    for cmd in info["commands"]:
        out += [".TP", f".B {roff(cmd['name'])}", roff(cmd["summary"])]
    out += [".PP", "Each command's arguments and options are listed under COMMANDS below;",
            ".B trivcon", ".I command", ".B \\-\\-help", "prints them too."]
    out.append(".SH OPTIONS")
    man_items(out, section(top, "Options"))
    out.append(".SH COMMANDS")
    for cmd in info["commands"]:
        out += [f'.SS "{roff(cmd["usage"])}"', roff(cmd["description"])]
        for title, items in cmd["sections"]:
            out += [".PP", f".I {roff(title)}"]
            man_items(out, items)
        if cmd["footer"]:
            out += [".PP", roff(cmd["footer"])]
    statuses = exit_statuses(top)
    if statuses:
        out.append(".SH EXIT STATUS")
        for code, desc in statuses:
            out += [".TP", f".B {roff(code)}", roff(desc)]
    if top["footer"]:
        out += [".SH NOTES", roff(top["footer"])]
    out += [".SH SEE ALSO", "The documentation site (scripts/docs.sh builds it into build/docs from docs/ in trivcon's source): tutorials, file formats, conventions, the C++ library and the Python module."]
    write(path, "\n".join(out) + "\n")


# markdown

def md(text):
    """Text for a Markdown table cell."""
    return text.replace("|", "\\|").replace("<", "&lt;")


def md_items(out, items, what):
    out += [f"| {what} | Description |", "| --- | --- |"]
    for name, desc in items:
        out.append(f"| `{name.replace('|', '&#124;')}` | {md(desc)} |")
    out.append("")


def write_markdown(info, folder):
    top, version, summary = info["top"], info["version"], info["summary"]
    out = [
        "<!-- Generated by scripts/cli_help.py from `trivcon --help`: do not edit. -->",
        "# Command-line reference",
        "",
        f"`trivcon` {version}: {md(summary)}.",
        "",
        "```",
        top["usage"],
        "```",
        "",
        "| Command | What it does |",
        "| --- | --- |",
    ]
    out += [f"| [`{c['name']}`](#trivcon-{c['name']}) | {md(c['summary'])} |" for c in info["commands"]]
    out.append("")
    md_items(out, section(top, "Options"), "Option")
    for cmd in info["commands"]:
        out += [f"## trivcon {cmd['name']}", "", md(cmd["description"]), "", "```", cmd["usage"], "```", ""]
        for title, items in cmd["sections"]:
            out += [f"**{title}**", ""]
            md_items(out, items, "Argument" if title.lower().startswith("positional") else "Option")
        if cmd["footer"]:
            out += [md(cmd["footer"]), ""]
    statuses = exit_statuses(top)
    if statuses:
        out += ["## Exit status", "", "| Status | Meaning |", "| --- | --- |"]
        out += [f"| {code} | {md(desc)} |" for code, desc in statuses]
        out.append("")
    if top["footer"]:
        out += [md(top["footer"]), ""]
    os.makedirs(folder, exist_ok=True)
    write(os.path.join(folder, "cli.md"), "\n".join(out))


# bash completion

def shell_words(words):
    return " ".join(words).replace("'", "")


def write_bash(info, path):
    top = info["top"]
    top_options = [n for name, _ in section(top, "Options") for n in option_names(name) if n.startswith("--")]
    cases_options, cases_values = [], []
    for cmd in info["commands"]:
        names, choices = [], []
        for name, _ in section(cmd, "Options"):
            opts = option_names(name)
            names += [n for n in opts if n.startswith("--")]
            if option_choices(name):
                choices.append((opts, option_choices(name)))
        cases_options.append(f"    {cmd['name']}) opts='{shell_words(names)}' ;;")
        for opts, values in choices:
            cases_values.append(f"    {cmd['name']}:{('|' + cmd['name'] + ':').join(opts)}) COMPREPLY=($(compgen -W '{shell_words(values)}' -- \"$cur\")); return ;;")
    commands = shell_words(c["name"] for c in info["commands"])
    text = f"""# SPDX-License-Identifier: MIT
# bash completion of trivcon {info['version']}. Generated by scripts/cli_help.py from `trivcon --help`: do not edit.
_trivcon() {{
  local cur=${{COMP_WORDS[COMP_CWORD]}} prev=${{COMP_WORDS[COMP_CWORD-1]}} cmd='' i opts
  for ((i = 1; i < COMP_CWORD; i++)); do
    case " {commands} " in *" ${{COMP_WORDS[i]}} "*) cmd=${{COMP_WORDS[i]}}; break ;; esac
  done
  if [ -z "$cmd" ]; then
    COMPREPLY=($(compgen -W '{commands} {shell_words(top_options)}' -- "$cur"))
    return
  fi
  case "$cmd" in
{chr(10).join(cases_options)}
  esac
  case "$cmd:$prev" in
{chr(10).join(cases_values)}
  esac
  if [[ "$cur" == -* ]]; then
    COMPREPLY=($(compgen -W "$opts" -- "$cur"))
  else
    COMPREPLY=($(compgen -f -- "$cur"))
  fi
}}
complete -o filenames -o bashdefault -F _trivcon trivcon
"""
    write(path, text)


def write(path, text):
    folder = os.path.dirname(os.path.abspath(path))
    os.makedirs(folder, exist_ok=True)
    tmp = path + ".tmp"
    with open(tmp, "w", encoding="utf-8") as f:
        f.write(text)
    os.replace(tmp, path)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--program", required=True, help="the trivcon program to run")
    parser.add_argument("--format", required=True, choices=["man", "markdown", "bash"])
    parser.add_argument("--out", required=True, help="man, bash: the file to write; markdown: the folder (gets cli.md)")
    args = parser.parse_args(argv)
    try:
        info = collect(args.program)
    except HelpError as e:
        print(f"cli_help.py: {e}", file=sys.stderr)
        return 1
    {"man": write_man, "markdown": write_markdown, "bash": write_bash}[args.format](info, args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
