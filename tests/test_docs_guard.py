"""The hand-written docs against the code (issue 31 item 5; datasette's practice of testing
the documentation): every `--option`, `[table] key` and backticked snake_case name the docs
give must exist — a renamed option, a removed key or a kernel function that is gone fails
here instead of misleading a reader. The generated references (cli.md, configuration.md,
outputs.md) have their own tests."""

from __future__ import annotations

import re

import pytest
from drillfric.cli.main import cli

from drillfric.config import SCHEMA
from tests.conftest import REPO

GENERATED = {"cli.md", "configuration.md", "outputs.md"}
DOCS = sorted(p for p in (REPO / "docs").glob("*.md") if p.name not in GENERATED) + \
    [REPO / "README.md"]
#: Names from other libraries the docs quote (not drillfric's to define).
FOREIGN = {"assert_frame_equal"}


def _options() -> set[str]:
    found = {"--help"}

    def walk(cmd):
        for param in cmd.params:
            found.update(o for o in param.opts + param.secondary_opts if o.startswith("--"))
        for sub in getattr(cmd, "commands", {}).values():
            walk(sub)

    walk(cli)
    return found


def _source() -> str:
    """The code the docs may name: the package, the CLI, benchmarks (their argparse options
    too), templates and tests."""
    return "\n".join(p.read_text(encoding="utf-8", errors="replace")
                     for folder in ("drillfric", "cli", "benchmarks", "templates", "tests")
                     for p in (REPO / folder).rglob("*")
                     if p.suffix in (".py", ".j2", ".html", ".js", ".toml"))


@pytest.fixture(scope="module")
def code():
    return _options(), _source()


def _missing(text: str, options: set[str], source: str) -> list[str]:
    found = [opt for opt in re.findall(r"`(--[a-z][a-z0-9-]*)", text)
             if opt not in options and f'"{opt}"' not in source]
    found += [f"[{table}] {key}" for table, key in re.findall(r"`\[(\w+)\]\s+(\w+)", text)
              if table in SCHEMA and key not in {k.name for k in SCHEMA[table]}]
    found += [name for name in re.findall(r"`([a-z][a-z0-9]*(?:_[a-z0-9]+)+)`", text)
              if name not in source and name not in FOREIGN]
    return sorted(set(found))


@pytest.mark.parametrize("doc", DOCS, ids=lambda p: p.name)
def test_what_the_docs_name_exists(doc, code):
    missing = _missing(doc.read_text(encoding="utf-8"), *code)
    assert not missing, f"{doc.name} names what the code does not have: {missing}"


def test_the_guard_catches_a_stale_name(code):
    """The guard itself: an option, a key and a name that do not exist are each caught
    (spelt here in pieces, so that this file does not define them)."""
    option, key, name = "--no-such-" + "option", "frob" + "nicate_s", "stale_" + "kernel_name"
    text = f"`{option}`, `[model] {key}`, `{name}`, `--out`, `[well] bit_depth_m`"
    assert _missing(text, *code) == sorted([option, f"[model] {key}", name])


def test_examples_readme_names_configurations_that_load():
    """Issue 35 item 6: examples/README.md shows how to run the real-log kinds; every
    configuration its commands and manifest name exists and loads."""
    from drillfric.config import load_config

    text = (REPO / "examples" / "README.md").read_text(encoding="utf-8")
    named = set(re.findall(r"examples/[\w./-]+\.toml", text))
    assert {"examples/dsats_1hz.toml", "examples/volve_f4.toml",
            "examples/usrop_f5.toml"} <= named
    for name in named:
        load_config(REPO / name)
