"""Print a pip constraints file that pins every dependency of pyproject.toml to its floor.

`.ci/run` installs abrupt with these constraints in its second leg and runs the whole suite there, so
that each floor in pyproject.toml is a version that was tested, not a guess.
"""

from __future__ import annotations

import re
import sys
import tomllib
from pathlib import Path

REQUIREMENT = re.compile(r"^\s*([A-Za-z0-9_.-]+)(?:\[[^\]]*\])?\s*>=\s*([^,;\s]+)\s*$")


def floors(pyproject: Path) -> dict[str, str]:
    project = tomllib.loads(pyproject.read_text(encoding="utf-8"))["project"]
    found: dict[str, str] = {}
    requirements = list(project["dependencies"])
    for extra in project.get("optional-dependencies", {}).values():
        requirements += extra
    for requirement in requirements:
        match = REQUIREMENT.match(requirement)
        if match is None:
            if ">=" in requirement or "==" not in requirement:
                sys.exit(f"{pyproject}: dependency {requirement!r} has no plain '>=' floor to pin")
            continue  # an exact pin (bsk==...) constrains itself
        found[match.group(1).lower()] = match.group(2)
    return found


if __name__ == "__main__":
    root = Path(__file__).resolve().parent.parent
    for name, version in sorted(floors(root / "pyproject.toml").items()):
        print(f"{name}=={version}")
