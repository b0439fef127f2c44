"""doc/parameters.md is what `parameter_reference` prints from the parameter structs (regenerate: scripts/docs)."""
import os
import re
import subprocess

import yaml

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
BIN = os.environ.get("MAF_BIN", os.path.join(ROOT, "build", "devel", "lib", "map_aided_fusion"))


def generated():
    return subprocess.run([os.path.join(BIN, "parameter_reference")], check=True, capture_output=True,
                          text=True, timeout=120).stdout


def test_checked_in_reference_is_what_the_structs_say():
    with open(os.path.join(ROOT, "doc", "parameters.md")) as f:
        checked_in = f.read()
    assert checked_in == generated(), "doc/parameters.md is stale: run scripts/docs"


def test_every_key_of_the_default_profile_is_documented_with_a_meaning():
    text = generated()
    rows = {m.group(1): m.group(2) for m in re.finditer(r"^\| `(\w+)` \|.*\| ([^|]*) \|$", text, re.M)}
    for name in ("prior_grid.yaml", "scan_grid.yaml", "fusion.yaml"):
        with open(os.path.join(ROOT, "config", name)) as f:
            keys = yaml.safe_load(f).keys()
        undocumented = [k for k in keys if k not in rows]
        assert not undocumented, f"config/{name}: keys missing from the reference: {undocumented}"
    assert all(meaning.strip() for meaning in rows.values()), "a parameter without a meaning"
