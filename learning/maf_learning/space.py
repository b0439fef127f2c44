"""The search space of the tuner and the configuration files of one parameter set.

A search space (learning/search_space.yaml) maps each configuration file of config/ (fusion.yaml, scan_grid.yaml,
prior_grid.yaml) to the parameters to search, each a range [lo, hi] (floats; integers when both ends are) or
{choices: [...]}. Every name must be a key of that file, every range non-empty and inside the interval the
parameter's own validation accepts (`evaluate --check-config`, the C++ structs' validate(): one source of truth).
"""
import json
import os
import re
import subprocess
import tempfile

import yaml

from .drives import PACKAGE_ROOT

CONFIG_FILES = ("fusion.yaml", "scan_grid.yaml", "prior_grid.yaml")
SENSOR_MARK = "IBEO:"  # lines of config/ibeo/*.yaml that belong to the sensor: never overridden
SENSOR_FILES = ("scan_grid.yaml", "fusion.yaml")  # the files of config/ibeo/
_LINE = re.compile(r"^(?P<key>[A-Za-z_][A-Za-z0-9_]*):(?P<sp>\s*)(?P<value>[^#\n]*?)(?P<rest>\s*(#.*)?)$")


class SpaceError(ValueError):
    """A search space that cannot be searched; the message names the item."""


class Param:
    def __init__(self, file, name, low=None, high=None, choices=None, integer=False):
        self.file, self.name = file, name
        self.low, self.high, self.choices, self.integer = low, high, choices, integer

    @property
    def key(self):
        return f"{self.file[:-5]}.{self.name}"

    def suggest(self, trial):
        if self.choices is not None:
            return trial.suggest_categorical(self.key, self.choices)
        if self.integer:
            return trial.suggest_int(self.key, self.low, self.high)
        return trial.suggest_float(self.key, self.low, self.high)

    def describe(self):
        if self.choices is not None:
            return f"{{{', '.join(map(str, self.choices))}}}"
        return f"[{self.low}, {self.high}]"


def config_keys(path):
    """The parameter names of a configuration file (its top-level keys)."""
    with open(path) as f:
        data = yaml.safe_load(f) or {}
    return set(data)


def base_values(config_dir):
    """{file: {key: value}} of a configuration directory."""
    out = {}
    for name in CONFIG_FILES:
        with open(os.path.join(config_dir, name)) as f:
            out[name] = yaml.safe_load(f) or {}
    return out


def load_space(path, config_dir=None):
    config_dir = config_dir or os.path.join(PACKAGE_ROOT, "config")
    try:
        with open(path) as f:
            data = yaml.safe_load(f) or {}
    except (OSError, yaml.YAMLError) as e:
        raise SpaceError(f"search space {path}: {e}")
    if not isinstance(data, dict):
        raise SpaceError(f"search space {path}: must map config files to parameters")
    params = []
    for file, entries in data.items():
        if file not in CONFIG_FILES:
            raise SpaceError(f"search space: '{file}' is not a configuration file ({', '.join(CONFIG_FILES)})")
        if entries is not None and not isinstance(entries, dict):
            raise SpaceError(f"search space: {file}: must map parameters to ranges ({{name: [lo, hi]}}), "
                             f"not {entries!r}")
        keys = config_keys(os.path.join(config_dir, file))
        for name, spec in (entries or {}).items():
            where = f"search space: {file}: {name}"
            if name not in keys:
                raise SpaceError(f"{where}: not a parameter of config/{file}")
            if isinstance(spec, dict):
                if set(spec) != {"choices"} or not isinstance(spec["choices"], list) or not spec["choices"]:
                    raise SpaceError(f"{where}: a categorical parameter is {{choices: [a, b, ...]}} (non-empty)")
                params.append(Param(file, name, choices=list(spec["choices"])))
                continue
            if not (isinstance(spec, list) and len(spec) == 2 and all(isinstance(v, (int, float)) and
                                                                        not isinstance(v, bool) for v in spec)):
                raise SpaceError(f"{where}: a range is [lo, hi] of numbers, or {{choices: [...]}}")
            lo, hi = spec
            if not lo < hi:
                raise SpaceError(f"{where}: the range [{lo}, {hi}] is empty")
            integer = isinstance(lo, int) and isinstance(hi, int)
            params.append(Param(file, name, low=lo if integer else float(lo), high=hi if integer else float(hi),
                                integer=integer))
    if not params:
        raise SpaceError(f"search space {path}: no parameter to search")
    return params


def format_value(v):
    """A YAML scalar: true/false, a number rounded to 6 decimals, a bare word or a quoted string."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        return repr(round(v, 6))
    if isinstance(v, int):
        return str(v)
    return v if re.fullmatch(r"[A-Za-z_][A-Za-z0-9_./-]*", str(v)) else json.dumps(str(v))


def render(base_text, values, keep_sensor_lines=False):
    """base_text (a config file) with the values of `values` ({key: value}) substituted, comments kept."""
    out, done = [], set()
    for line in base_text.splitlines(keepends=True):
        m = _LINE.match(line.rstrip("\n"))
        if m and m.group("key") in values and not (keep_sensor_lines and SENSOR_MARK in line):
            key = m.group("key")
            value = format_value(values[key])
            line = f"{key}:{m.group('sp') or ' '}{value}{m.group('rest') or ''}\n"
            done.add(key)
        out.append(line)
    missing = set(values) - done
    if missing and not keep_sensor_lines:
        raise SpaceError(f"not in the configuration file: {', '.join(sorted(missing))}")
    return "".join(out)


def write_config_dir(out_dir, values_by_file, config_dir=None, header=None):
    """Writes out_dir/{fusion,scan_grid,prior_grid}.yaml and out_dir/ibeo/{scan_grid,fusion}.yaml from config_dir
    (config/ by default) with the values substituted (the IBEO files keep their sensor lines)."""
    config_dir = config_dir or os.path.join(PACKAGE_ROOT, "config")
    os.makedirs(os.path.join(out_dir, "ibeo"), exist_ok=True)
    for name in CONFIG_FILES:
        with open(os.path.join(config_dir, name)) as f:
            text = render(f.read(), values_by_file.get(name, {}))
        with open(os.path.join(out_dir, name), "w") as f:
            f.write((header or "") + text)
    for name in SENSOR_FILES:
        ibeo_base = os.path.join(config_dir, "ibeo", name)
        if not os.path.isfile(ibeo_base):
            ibeo_base = os.path.join(PACKAGE_ROOT, "config", "ibeo", name)
        with open(ibeo_base) as f:
            text = render(f.read(), values_by_file.get(name, {}), keep_sensor_lines=True)
        with open(os.path.join(out_dir, "ibeo", name), "w") as f:
            f.write((header or "") + text)


def split_values(flat):
    """{'fusion.alpha_static': 0.1, ...} (optuna's names) -> {'fusion.yaml': {'alpha_static': 0.1}, ...}."""
    out = {}
    for key, value in flat.items():
        file, name = key.split(".", 1)
        out.setdefault(file + ".yaml", {})[name] = value
    return out


def check_config_dir(evaluate, config_dir):
    """None when `evaluate --check-config` accepts the directory (and its ibeo/ files, when it has them), else its
    one-line error."""
    sensor = os.path.join(config_dir, "ibeo")
    sets = [(config_dir, config_dir)]
    if all(os.path.isfile(os.path.join(sensor, n)) for n in SENSOR_FILES):
        sets.append((sensor, sensor))
    for fusion_dir, scan_dir in sets:
        cmd = [evaluate, "--check-config", "--fusion-config", os.path.join(fusion_dir, "fusion.yaml"),
               "--scan-grid-config", os.path.join(scan_dir, "scan_grid.yaml"),
               "--prior-config", os.path.join(config_dir, "prior_grid.yaml")]
        r = subprocess.run(cmd, capture_output=True, text=True, timeout=60)
        if r.returncode != 0:
            lines = [ln.strip() for ln in r.stderr.splitlines() if ln.strip()]
            return (lines[-1] if lines else f"exit {r.returncode}").replace("evaluate: ", "")
    return None


def validate_ranges(params, evaluate, config_dir=None):
    """Raises SpaceError naming the first parameter whose range leaves its valid interval. Every parameter at its
    low end, then at its high end, in two checks; a failing check is repeated per parameter to name it."""
    with tempfile.TemporaryDirectory(prefix="maf_space_") as tmp:
        def check(assignment):
            values = {}
            for p, v in assignment:
                values.setdefault(p.file, {})[p.name] = v
            write_config_dir(tmp, values, config_dir)
            return check_config_dir(evaluate, tmp)

        ends = [[(p, (p.choices if p.choices is not None else [p.low, p.high])[k]) for p in params] for k in (0, -1)]
        for together in ends:
            if check(together) is None:
                continue
            for p, v in together:
                err = check([(p, v)])
                if err:
                    raise SpaceError(f"search space: {p.file}: {p.name}: {p.describe()} leaves the valid interval "
                                     f"({err})")
        for p in params:
            for v in (p.choices or [])[1:-1]:
                err = check([(p, v)])
                if err:
                    raise SpaceError(f"search space: {p.file}: {p.name}: {p.describe()} leaves the valid interval "
                                     f"({err})")
