"""package.xml against what rosdep can resolve, and the optional extras kept out of it."""
import os
import xml.etree.ElementTree as ET

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))


def dependencies():
    root = ET.parse(os.path.join(ROOT, "package.xml")).getroot()
    return sorted({e.text.strip() for e in root if e.tag.endswith("depend")})


def listed_keys():
    with open(os.path.join(os.path.dirname(__file__), "rosdep_keys.txt")) as f:
        return {ln.strip() for ln in f if ln.strip() and not ln.startswith("#")}


def test_every_dependency_is_a_key_rosdep_resolves():
    deps = dependencies()
    unknown = [d for d in deps if d not in listed_keys()]
    assert not unknown, f"not checked against rosdistro (test/package/rosdep_keys.txt): {unknown}"


def test_learning_extras_and_servers_are_not_dependencies():
    deps = dependencies()
    for extra in ("python3-optuna", "python3-psycopg2", "python3-matplotlib", "postgresql"):
        assert extra not in deps, f"{extra} is an optional extra, not a dependency of the package"
