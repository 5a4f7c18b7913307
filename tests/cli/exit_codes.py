"""README.md's exit-code table is the one the binary renders into `quadcosim --help` (its footer,
from app/exit_codes.cpp): the same rows, in the same order, with the same commands.
   usage: exit_codes.py QUADCOSIM_BINARY README.md"""
import re
import subprocess
import sys

qc, readme = sys.argv[1], sys.argv[2]
help_text = subprocess.run([qc, "--help"], capture_output=True, text=True, check=True).stdout
footer = help_text.split("Exit codes:", 1)[1]
from_code = []
for line in footer.strip().splitlines():
    m = re.match(r"\s*(\d+)\s+(.*?)(?: \(([a-z ]+)\))?$", line)
    from_code.append((m.group(1), m.group(2), m.group(3) or "every command"))

text = open(readme, encoding="utf-8").read()
section = text.split("<!-- exit-codes -->", 2)
if len(section) != 3:
    sys.exit("README.md: no exit-code table between two <!-- exit-codes --> markers")
from_readme = []
for line in section[1].strip().splitlines()[2:]:
    cells = [c.strip().strip("`") for c in line.strip().strip("|").split("|")]
    from_readme.append(tuple(cells))
if from_readme != from_code:
    print("README.md exit codes differ from quadcosim --help:")
    for row in from_code:
        print(("  " if row in from_readme else "- missing in README: ") + " | ".join(row))
    for row in from_readme:
        if row not in from_code:
            print("+ only in README: " + " | ".join(row))
    sys.exit(1)
print(f"ok: {len(from_code)} rows agree")
