"""Every key of the shipped configuration files is a parameter some component reads: the nodelets refuse unknown
keys (param_loading.hpp, refuseUnknownParams), so a key that no code reads would stop a profile from starting."""
import glob
import os
import re

import yaml

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))


def read_names():
    names = set()
    pattern = re.compile(r'(?:get|readParam\(\w+,)\s*\(?\s*"([A-Za-z_][A-Za-z0-9_]*)"')
    for path in glob.glob(os.path.join(ROOT, "include", "**", "*.hpp"), recursive=True) + \
            glob.glob(os.path.join(ROOT, "src", "**", "*.cpp"), recursive=True):
        with open(path) as f:
            names.update(pattern.findall(f.read()))
    return names


def test_every_config_key_is_read_by_the_code():
    known = read_names()
    assert {"alpha_static", "min_valid_returns", "max_vehicle_distance", "base_frame"} <= known, "the scan is broken"
    unknown = {}
    for path in glob.glob(os.path.join(ROOT, "config", "**", "*.yaml"), recursive=True):
        with open(path) as f:
            data = yaml.safe_load(f) or {}
        missing = sorted(k for k in data if k not in known)
        if missing:
            unknown[os.path.relpath(path, ROOT)] = missing
    assert not unknown, f"keys no component reads: {unknown}"
