"""One command-line dialect: every `gsdf` subcommand spells and validates the options it shares with the others
the same way (walks the click parameters of every command; no command is run)."""

import collections

import click
import pytest
from click.testing import CliRunner

from gsdf.cli import _options
from gsdf.cli.main import SECTIONS, main

COMMANDS = sorted(main.commands)

# commands that write a folder (-o/--output-dir) or nothing at all; every other command writes one file (-o/--output)
FOLDER_OUTPUT = {"batch", "demo"}
NO_OUTPUT = {"warmup"}

# spellings that were replaced by the one dialect (the replacement in the comment); none may come back visible
RETIRED = {
    "--out": "--output-dir (hidden alias for one release)",
    "--grid": "--resolution",
    "--mesh-out": "--mesh-output",
    "--surface": "--mesh-output",
    "--surface-out": "--mesh-output",
    "--constraint": "--level-set",
    "--jobs": "--workers",
    "--n-samples": "--n-points",
    "--heat-resolution": "--resolution",
    "--output-folder": "--output-dir",
}

# options whose values are a per-command set of choices (each command has its own methods / sign rules)
PER_COMMAND_CHOICES = {"--method", "--sign"}

# shared options and the one type object that validates them, wherever they appear
SHARED_TYPES = {
    "--resolution": _options.RESOLUTION,
    "--pad": _options.PAD,
    "--threads": _options.THREADS,
    "--beta": _options.POSITIVE,
    "--t-coef": _options.POSITIVE,
    "--soft-weight": _options.POSITIVE,
    "--level-set": _options.LEVEL_SET,
    "--view": _options.DIRECTION,
    "--offsets": _options.FLOATS,
    "--bisection": _options.BISECTION,
    "--level": _options.NUMBER,
    "--at": _options.NUMBER,
    "--axis": _options.AXIS,
    "--workers": _options.COUNT,
    "--png": click.STRING,
    "--mesh-output": click.STRING,
}


def options(cmd):
    return [p for p in cmd.params if isinstance(p, click.Option)]


def visible(cmd):
    return [p for p in options(cmd) if not p.hidden]


def by_long_name(cmd):
    out = {}
    for p in visible(cmd):
        for o in p.opts + p.secondary_opts:
            if o.startswith("--"):
                out[o] = p
    return out


def test_every_command_is_listed_once_in_the_grouped_help():
    listed = [n for _, names in SECTIONS for n in names]
    assert sorted(listed) == COMMANDS, "every command belongs to exactly one section of `gsdf --help`"
    r = CliRunner().invoke(main, ["--help"])
    assert r.exit_code == 0, r.output
    for title, names in SECTIONS:
        assert f"\n{title}:\n" in r.output
    # in section order
    positions = [r.output.index(f"\n  {n} ") for n in listed]
    assert positions == sorted(positions)


@pytest.mark.parametrize("name", COMMANDS)
def test_help_works_and_shows_the_shared_flags(name):
    r = CliRunner().invoke(main, [name, "--help"])
    assert r.exit_code == 0, r.output
    assert "-q, --quiet" in r.output and "--threads N" in r.output
    assert "Example" in r.output
    for old in RETIRED:
        assert f"{old} " not in r.output and f"{old}\n" not in r.output, f"gsdf {name} --help mentions {old}"
    for word in ("bench/", "RESULTS", "issue "):
        assert word not in r.output, f"gsdf {name} --help mentions {word!r}"


@pytest.mark.parametrize("name", COMMANDS)
def test_quiet_and_threads_on_every_command(name):
    cmd = main.commands[name]
    opts = {tuple(p.opts): p for p in options(cmd)}
    quiet = opts.get(("-q", "--quiet"))
    assert quiet is not None and quiet.is_flag, f"gsdf {name}: no -q/--quiet"
    threads = opts.get(("--threads",))
    assert threads is not None and threads.type is _options.THREADS, f"gsdf {name}: no shared --threads"


@pytest.mark.parametrize("name", COMMANDS)
def test_outputs_are_spelled_one_way(name):
    cmd = main.commands[name]
    short_o = [p for p in options(cmd) if "-o" in p.opts]
    if name in NO_OUTPUT:
        assert not short_o
        return
    assert len(short_o) == 1, f"gsdf {name}: one -o"
    want = ["-o", "--output-dir"] if name in FOLDER_OUTPUT else ["-o", "--output"]
    if name == "view":              # the contract (design notes) names it --screenshot: one option, two names
        want = want + ["--screenshot"]
    assert short_o[0].opts == want, f"gsdf {name}: -o is {short_o[0].opts}, want {want}"
    assert short_o[0].name == want[1][2:].replace("-", "_")
    # no other visible option names an output with another spelling
    for o in by_long_name(cmd):
        if {"out", "output", "outputs", "dir", "folder"} & set(o[2:].split("-")):
            assert o in ("--output", "--output-dir", "--mesh-output"), f"gsdf {name}: {o}"
    # the hidden --out is the folder commands' old name only
    hidden = [o for p in options(cmd) if p.hidden for o in p.opts]
    assert hidden == (["--out"] if name in FOLDER_OUTPUT else [])


def test_secondary_outputs_are_spelled_one_way():
    for name in COMMANDS:
        names = by_long_name(main.commands[name])
        for o, p in names.items():
            if o in ("--png", "--mesh-output"):
                assert p.opts == [o] and p.name == o[2:].replace("-", "_"), f"gsdf {name}: {o}"


@pytest.mark.parametrize("name", COMMANDS)
def test_no_retired_spelling(name):
    names = by_long_name(main.commands[name])
    for old, new in RETIRED.items():
        assert old not in names, f"gsdf {name} {old}: spelled {new} now"


def test_shared_options_are_one_option():
    """Across commands, one long name has one destination name, one set of flags and one type object; one
    destination name has one long name."""
    flags = collections.defaultdict(set)
    dest = collections.defaultdict(set)
    types = collections.defaultdict(list)
    for name in COMMANDS:
        for o, p in by_long_name(main.commands[name]).items():
            # gsdf view's -o/--output also answers to --screenshot (the name its contract gives)
            flags[o].add(tuple(f for f in p.opts + p.secondary_opts if f != "--screenshot"))
            dest[o].add(p.name)
            types[o].append((name, p.type))
    for o in flags:
        assert len(flags[o]) == 1, f"{o} is spelled {flags[o]}"
        assert len(dest[o]) == 1, f"{o} is stored as {dest[o]}"
        if o in PER_COMMAND_CHOICES:
            continue
        first = types[o][0][1]
        odd = [n for n, t in types[o] if t is not first and not (isinstance(t, click.types.BoolParamType)
                                                                  and isinstance(first, click.types.BoolParamType))]
        assert not odd, f"{o}: {odd} validate it with another type than {types[o][0][0]}"
    names_of = collections.defaultdict(set)
    for o, ds in dest.items():
        for d in ds:
            names_of[d].add(tuple(sorted(f for fl in flags[o] for f in fl)))
    for d, spellings in names_of.items():
        assert len(spellings) == 1, f"one meaning ({d}), several spellings: {spellings}"


@pytest.mark.parametrize("option,kind", sorted(SHARED_TYPES.items()))
def test_shared_options_use_the_one_type(option, kind):
    seen = 0
    for name in COMMANDS:
        p = by_long_name(main.commands[name]).get(option)
        if p is not None:
            seen += 1
            assert p.type is kind, f"gsdf {name} {option}: {p.type!r} is not the shared {kind!r}"
    assert seen, f"no command has {option}"


def test_shared_flags_are_one_definition():
    """A flag that several commands take (--exact, --estimate-normals, --no-clobber, -q) is defined once: the
    same flags and the same help everywhere."""
    seen = collections.defaultdict(set)
    for name in COMMANDS:
        for o, p in by_long_name(main.commands[name]).items():
            if p.is_flag and not p.secondary_opts:
                seen[o].add((tuple(p.opts), p.help))
    assert {"--exact", "--estimate-normals", "--no-clobber", "--quiet"} <= set(seen)
    for o, defs in seen.items():
        assert len(defs) == 1, f"{o}: {defs}"


def test_pad_means_a_fraction_of_the_diagonal_everywhere():
    helps = {p.help for name in COMMANDS for o, p in by_long_name(main.commands[name]).items() if o == "--pad"}
    assert len(helps) == 1 and "diagonal" in helps.pop()


@pytest.mark.parametrize("option,bad", [("--resolution", "1"), ("--pad", "-0.1"), ("--pad", "nan"),
                                        ("--soft-weight", "0"), ("--t-coef", "inf"), ("--view", "0,0,0"),
                                        ("--threads", "0"), ("--beta", "-1")])
def test_shared_validation_refuses_the_same_values_everywhere(option, bad):
    for name in COMMANDS:
        p = by_long_name(main.commands[name]).get(option)
        if p is None:
            continue
        with pytest.raises(click.BadParameter):
            p.type.convert(bad, p, None)


def test_command_threads_is_the_group_threads(monkeypatch):
    from gsdf import threads

    calls = []
    monkeypatch.setattr(threads, "set_num_threads", lambda n: calls.append(n))
    r = CliRunner().invoke(main, ["warmup", "--threads", "0", "--only", "nonsense"])
    assert r.exit_code == 2 and "--threads" in r.output and "positive integer" in r.output and not calls
    # a valid value is applied (as `gsdf --threads 3` does) before the command runs (here: fails on --only)
    r = CliRunner().invoke(main, ["warmup", "--threads", "3", "--only", "nonsense"])
    assert r.exit_code == 1 and calls == [3]
    r = CliRunner().invoke(main, ["--threads", "2", "warmup", "--only", "nonsense"])
    assert r.exit_code == 1 and calls == [3, 2]


def test_out_is_a_hidden_alias_of_output_dir(tmp_path):
    f = tmp_path / "afile"
    f.write_text("x")
    # the old spelling reaches the same check as -o/--output-dir (a folder that is a file is refused)
    r = CliRunner().invoke(main, ["demo", "--out", str(f)])
    assert r.exit_code == 1 and "not a folder" in r.output and "--out is deprecated" in r.output
    r = CliRunner().invoke(main, ["demo", "--output-dir", str(f)])
    assert r.exit_code == 1 and "not a folder" in r.output
    r = CliRunner().invoke(main, ["batch", str(tmp_path), "--task", "occupancy"])
    assert r.exit_code == 2 and "--output-dir" in r.output
