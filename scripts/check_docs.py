#!/usr/bin/env python3
"""Every public function has a doc comment, and every module an example: run by ctest as
test_docs.

A declaration `AK_API ...;` in include/animkit/*.h counts as documented when a comment ends on
the line above it (or above the group of declarations it belongs to, with no blank line
between), or when the declaration itself carries a trailing comment. A module (a public header
other than the umbrella animkit.h) has an example when examples/ holds a file named
<module>_*.c or <module>_*.json. Prints each undocumented function as FILE:LINE: NAME and each
module without an example, and exits 1 if there is any."""
import glob
import os
import re
import sys


def undocumented(header):
    lines = open(header, encoding="utf-8").read().split("\n")
    out = []
    for i, line in enumerate(lines):
        if not line.startswith("AK_API"):
            continue
        # the declaration's own lines, up to its ';'
        k, decl = i, ""
        while k < len(lines):
            decl += lines[k]
            if ";" in lines[k] or "{" in lines[k]:
                break
            k += 1
        if "/*" in decl or "//" in decl:
            continue
        j, documented = i - 1, False
        while j >= 0:
            s = lines[j].strip()
            if s == "" or s.startswith("#"):
                break
            if s.endswith("*/") or s.startswith("//"):
                documented = True
                break
            j -= 1
        if not documented:
            m = re.search(r"(ak_\w+)\s*\(", decl)
            out.append(f"{header}:{i + 1}: {m.group(1) if m else line.strip()}")
    return out


def main():
    root = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..")
    headers = sorted(glob.glob(os.path.join(root, "include", "animkit", "*.h")))
    if not headers:
        print(f"no headers under {root}/include/animkit")
        return 1
    bad = [b for h in headers for b in undocumented(h)]
    count = sum(open(h, encoding="utf-8").read().count("\nAK_API") for h in headers)
    for b in bad:
        print(b)
    print(f"{count} public declarations in {len(headers)} headers, {len(bad)} without a doc comment")
    modules = [os.path.basename(h)[:-2] for h in headers if not h.endswith("animkit.h")]
    examples = os.listdir(os.path.join(root, "examples"))
    missing = [m for m in modules
               if not any(e.startswith(m + "_") and e.endswith((".c", ".json")) for e in examples)]
    for m in missing:
        print(f"module {m} (include/animkit/{m}.h) has no example: add examples/{m}_<what>.c")
    print(f"{len(modules)} modules, {len(missing)} without an example")
    return 1 if bad or missing else 0


if __name__ == "__main__":
    sys.exit(main())
