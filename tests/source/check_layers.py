#!/usr/bin/env python3
"""The folders of src/ form layers (docs/conventions.md, the `layers:` line): a module may use
modules of its own folder and of the folders below it, never one above.

Reads every `use` statement of src/**/*.f90, *.F90, *.inc and *.f90.in, maps each used module to the
folder that defines it, and fails on a use that points up, on a folder that is missing from the
layer list, and on a module that is neither defined in src/ nor a known external module (so a typo
in the check cannot hide a dependency).

usage: check_layers.py [SOURCE_ROOT]      (default: the repository this file is in)
"""
import os
import re
import sys

EXTERNAL_MODULES = {
    "iso_fortran_env", "iso_c_binding", "ieee_arithmetic", "ieee_exceptions", "ieee_features",
    "mpi_f08", "mpi", "hdf5", "h5lt", "omp_lib",
}
MODULE_RE = re.compile(r"^\s*module\s+(\w+)\s*(?:!.*)?$", re.IGNORECASE | re.MULTILINE)
# after `use` a space, `::` or `, intrinsic ::`: a variable such as `uses_spin = ...` is no use statement
USE_RE = re.compile(r"^\s*use(?:\s*,\s*(?:intrinsic|non_intrinsic)\s*::|\s*::|\s)\s*(\w+)",
                    re.IGNORECASE | re.MULTILINE)


def read_layers(root):
    conventions = os.path.join(root, "docs", "conventions.md")
    with open(conventions, encoding="utf-8") as handle:
        for line in handle:
            match = re.match(r"^\s*layers:\s*(.+)$", line)
            if match:
                return [name.strip() for name in match.group(1).split("<")]
    sys.exit(f"check_layers: no 'layers:' line in {conventions}")


def source_files(root):
    for folder, _, names in os.walk(os.path.join(root, "src")):
        for name in sorted(names):
            if name.endswith((".f90", ".F90", ".inc", ".f90.in")):
                yield os.path.join(folder, name)


def main():
    root = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else
                           os.path.join(os.path.dirname(__file__), "..", ".."))
    layers = read_layers(root)
    rank = {folder: index for index, folder in enumerate(layers)}
    defined_in = {}
    uses = []
    failures = []
    for path in source_files(root):
        relative = os.path.relpath(path, root)
        folder = relative.split(os.sep)[1]
        if folder not in rank:
            failures.append(f"{relative}: folder src/{folder} is not in the layers of docs/conventions.md")
            continue
        text = open(path, encoding="utf-8").read()
        for module in MODULE_RE.findall(text):
            if module.lower() not in ("procedure", "subroutine", "function"):
                defined_in[module.lower()] = folder
        for line_number, module in ((text.count("\n", 0, m.start()) + 1, m.group(1))
                                    for m in USE_RE.finditer(text)):
            uses.append((relative, line_number, folder, module.lower()))
    checked = 0
    for relative, line_number, folder, module in uses:
        if module in EXTERNAL_MODULES:
            continue
        if module not in defined_in:
            failures.append(f"{relative}:{line_number}: uses {module}, which no file of src/ defines")
            continue
        checked += 1
        target = defined_in[module]
        if rank[target] > rank[folder]:
            failures.append(f"{relative}:{line_number}: {folder} uses {module} of {target}, "
                            f"a layer above it ({' < '.join(layers)})")
    for failure in failures:
        print("FAIL", failure)
    print(f"{checked} use statements between src/ modules checked against {len(layers)} layers; "
          f"{len(failures)} failed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
