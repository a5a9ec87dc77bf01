"""Did you mean …? — the one suggestion for a near-miss name, used by every command.

A misspelt parameter key (``--set bearing.clearence=…``, a ``--params`` file's key, an error entry's field), scene
option (``--option frme=fixed``), option name (``--condtions``), choice (``--method hht-adaptiv``, a fault, an oil
grade, a scenario of ``dpgt``) ends in one line that names the closest valid names: :func:`did_you_mean` gives the
words, :func:`argparse_hint` adds them to argparse's own messages (unknown options, invalid choices).
"""
from __future__ import annotations

import difflib
import re
from typing import Iterable

__all__ = ["did_you_mean", "close_names", "argparse_hint"]


def close_names(word, choices: Iterable, n: int = 3, cutoff: float = 0.75) -> list[str]:
    """The valid names closest to ``word`` (case-insensitive; an exact match but for case first), best first."""
    names = list(dict.fromkeys(str(c) for c in choices))
    w = str(word).strip()
    by_lower: dict[str, str] = {}
    for name in names:
        by_lower.setdefault(name.lower(), name)
    same = [by_lower[w.lower()]] if w.lower() in by_lower and by_lower[w.lower()] != w else []
    scored = sorted(((-difflib.SequenceMatcher(None, w.lower(), low).ratio(), low) for low in by_lower))
    scored = [(-r, low) for r, low in scored]
    best = scored[0][0] if scored else 0.0
    # the best and those nearly as close: a clear near miss names one, not three
    close = [by_lower[low] for r, low in scored if r >= cutoff and r >= best - 0.05]
    return list(dict.fromkeys(same + [c for c in close if c != w]))[:n]


def did_you_mean(word, choices: Iterable, n: int = 3) -> str:
    """``" (did you mean 'x'?)"``, ``" (did you mean 'x' or 'y'?)"`` for the names of ``choices`` closest to
    ``word``; ``""`` when none is close."""
    close = close_names(word, choices, n)
    if not close:
        return ""
    quoted = [repr(c) for c in close]
    return f" (did you mean {quoted[0] if len(quoted) == 1 else ', '.join(quoted[:-1]) + ' or ' + quoted[-1]}?)"


_UNRECOGNIZED = re.compile(r"^unrecognized arguments: (.*)$")
_INVALID_CHOICE = re.compile(r"invalid choice: '([^']*)' \(choose from (.*)\)$")


def argparse_hint(parser, message: str) -> str:
    """argparse's error ``message`` with a suggestion: an unknown option gets the closest option names of
    ``parser``, an invalid choice the closest of its choices."""
    m = _UNRECOGNIZED.match(message)
    if m:
        options = [s for s in getattr(parser, "_option_string_actions", {}) if s.startswith("--")]
        for word in m.group(1).split():
            flag = word.split("=", 1)[0]
            if flag.startswith("-"):
                hint = did_you_mean(flag, options)
                if hint:
                    return f"{message}{hint}"
        return message
    m = _INVALID_CHOICE.search(message)
    if m:
        choices = re.findall(r"'([^']*)'", m.group(2))
        return f"{message}{did_you_mean(m.group(1), choices)}"
    return message
