"""Writes the command-line reference (Markdown) from the argument parsers of the installed package:
`ambfplus.cli.build_parser()` (the `ambfplus` command and its subcommands) and
`ambfplus.launcher.build_parser()` (`ambfplus-launch`).

    python docs/hooks/cli_reference.py     # prints the page's generated part

Run it from outside the source folder (the docs hook does), so that the installed package, with
its compiled engine, is the one imported.
"""

from __future__ import annotations

import argparse
import importlib
import sys


def parser_of(module_name: str) -> argparse.ArgumentParser:
    """The command line of a module, from its build_parser()."""
    return importlib.import_module(module_name).build_parser()


def _cell(text: str) -> str:
    return " ".join(str(text).split()).replace("|", "&#124;")


def _names(action: argparse.Action) -> str:
    if action.option_strings:
        names = ", ".join(f"`{o}`" for o in action.option_strings)
        if action.nargs != 0:
            metavar = action.metavar or action.dest.upper()
            if action.choices and not action.metavar:
                metavar = "{" + ",".join(map(str, action.choices)) + "}"
            names += f" `{metavar}`"
        return names
    return f"`{action.metavar or action.dest}`"


def _help(parser: argparse.ArgumentParser, action: argparse.Action) -> str:
    text = action.help or ""
    if "%(" in text:
        params = dict(vars(action), prog=parser.prog)
        params = {k: getattr(v, "__name__", v) for k, v in params.items()}
        text = text % params
    default = action.default
    shown = default not in (None, False, argparse.SUPPRESS, "") and action.nargs != 0
    if shown and "default" not in text:
        text += f" (default: `{default}`)"
    return _cell(text)


def render_parser(parser: argparse.ArgumentParser, level: int, out: list[str]) -> None:
    out.append(f"{'#' * level} `{parser.prog}`\n")
    if parser.description:
        out.append(parser.description.strip() + "\n")
    usage = parser.format_usage().strip().removeprefix("usage: ")
    out.append(f"```text\n{usage}\n```\n")
    rows = []
    subcommands = []
    for action in parser._actions:
        if isinstance(action, argparse._HelpAction) or action.help == argparse.SUPPRESS:
            continue
        if isinstance(action, argparse._SubParsersAction):
            helps = {a.dest: a.help for a in action._choices_actions}
            subcommands = [(name, helps.get(name, ""), p) for name, p in action.choices.items()]
            continue
        rows.append(f"| {_names(action)} | {_help(parser, action)} |")
    if rows:
        out.append("| argument | meaning |\n|---|---|")
        out.extend(rows)
        out.append("")
    if subcommands:
        out.append("| command | what it does |\n|---|---|")
        out.extend(f"| `{name}` | {_cell(help or '')} |" for name, help, _ in subcommands)
        out.append("")
        for _, _, sub in subcommands:
            render_parser(sub, min(level + 1, 4), out)


def render() -> str:
    out: list[str] = []
    render_parser(parser_of("ambfplus.cli"), 2, out)
    render_parser(parser_of("ambfplus.launcher"), 2, out)
    return "\n".join(out) + "\n"


if __name__ == "__main__":
    sys.stdout.write(render())
