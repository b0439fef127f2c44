#!/usr/bin/env python3
"""Reads the JUnit XML files that catkin's run_tests writes and prints 'N passed, N failed'."""
import pathlib
import sys
import xml.etree.ElementTree as ET


def main(results_dir):
    passed = failed = skipped = 0
    failures = []
    files = sorted(pathlib.Path(results_dir).rglob("*.xml"))
    for path in files:
        try:
            root = ET.parse(path).getroot()
        except ET.ParseError as err:
            failed += 1
            failures.append(f"{path.name}: unreadable result file ({err})")
            continue
        cases = list(root.iter("testcase"))
        if not cases and root.tag in ("testsuite", "testsuites"):
            # A file without test cases but with failures (e.g. a crashed gtest binary).
            if int(root.get("failures", 0)) + int(root.get("errors", 0)) > 0:
                failed += 1
                failures.append(f"{path.name}: test binary failed without results")
        for case in cases:
            name = f"{case.get('classname', '')}.{case.get('name', '')}"
            if case.find("failure") is not None or case.find("error") is not None:
                failed += 1
                failures.append(f"{path.name}: {name}")
            elif case.find("skipped") is not None or case.get("status") == "notrun":
                skipped += 1
            else:
                passed += 1
    for f in failures:
        print(f"FAILED: {f}")
    if not files:
        print("no test result files found", file=sys.stderr)
        failed += 1
    line = f"{passed} passed, {failed} failed"
    if skipped:
        line += f", {skipped} skipped"
    print(line)
    return 0 if failed == 0 and passed > 0 else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else "build/test_results"))
