"""Variants of a scene file without copying it by hand: set namelist variables in chosen groups.

A namelist read keeps the last value given to a variable, so a variant is the original text with
`name = value` appended at the end of the group it belongs to; the file's comments and layout stay.

    from scene_variant import write_variant
    write_variant("inputs/hydrostatic_tank.nml", "tank45.nml",
                  {"grid": {"rotation": "45.0"}, "material:water": {"stabilization": "'C0'"},
                   "run": {"output_dir": "'out/tank45'"}})

A group key is the group name, or `group:name` for the occurrence of a repeated group whose `name`
(or, for &body and &inlet, `material`) is that value. Values are Fortran text: quote strings.
"""

import re


def _group_end(text, start):
    """Index of the `/` that closes the group starting at `start` (skips strings and comments)."""
    quote = None
    i = start
    while i < len(text):
        c = text[i]
        if quote:
            if c == quote:
                quote = None
        elif c in "'\"":
            quote = c
        elif c == "!":
            newline = text.find("\n", i)
            i = len(text) if newline < 0 else newline
            continue
        elif c == "/":
            return i
        i += 1
    raise ValueError("group starting at character %d is not closed" % start)


def _groups(text, group):
    """(start, end) of every `&group` in text, in file order."""
    found = []
    for match in re.finditer(r"(?im)^[ \t]*&" + re.escape(group) + r"\b", text):
        found.append((match.start(), _group_end(text, match.end())))
    return found


def set_variables(text, changes):
    """The scene text with the variables of `changes` ({group key: {name: value}}) set."""
    for key, values in changes.items():
        group, _, selector = key.partition(":")
        spans = _groups(text, group)
        if selector:
            pattern = re.compile(r"(?i)\b(name|material)\s*=\s*['\"]" + re.escape(selector) + r"['\"]")
            spans = [span for span in spans if pattern.search(text[span[0]:span[1]])]
        if not spans:
            if selector or group not in ("run", "grid", "box_walls", "gravity"):
                raise ValueError("no group &%s in the scene" % key)
            text += "\n&%s\n/\n" % group
            spans = _groups(text, group)
        start, end = spans[0]
        addition = "".join("\n   %s = %s" % (name, value) for name, value in values.items())
        text = text[:end] + addition + "\n" + text[end:]
    return text


def write_variant(source, target, changes):
    with open(source) as f:
        text = f.read()
    with open(target, "w") as f:
        f.write(set_variables(text, changes))
    return target
