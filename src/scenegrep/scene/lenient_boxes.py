"""How the position tolerance enters Scenic's implicit requirements about boxes: leniently.

A labeled position is known up to the position tolerance t, so an implicit requirement (no
collision, containment in ``regionContainedIn``, visibility) holds when it holds for *some*
positions within t of the labels. (The ``require`` statements a program states are evaluated on
the labeled values exactly: their box predicates keep ease 0.) For the predicates on object
boxes this means, by where they occur in the requirement:

* in positive position (under an even number of ``not``): lenient — a box is shrunk by t on
  every side to test that it lies inside a region, grown by t to test that it meets another box
  or a view sector;
* in negative position: strict — the other way round, so ``not`` of the predicate is lenient;
* anywhere else (a condition inside ``X if C else Y``): exactly as labeled.

:func:`eased` sets each box predicate's last argument, its *ease*, to +1, -1 or 0; the evaluator
adjusts the box sizes by ``2 t ease`` (grow) or ``-2 t ease`` (shrink) accordingly.
"""

from __future__ import annotations

from .terms import Term, TermFactory

BOX_PREDICATES = ("box_in_region", "boxes_overlap", "box_visible")


def eased(f: TermFactory, term: Term, polarity: int = 1, memo: dict | None = None) -> Term:
    """The condition with every box predicate's ease set by its polarity (see the module docstring)."""
    memo = {} if memo is None else memo
    key = (id(term), polarity)
    if key in memo:
        return memo[key]
    if term.op in BOX_PREDICATES:
        result = f.op(term.op, *term.args[:-1], f.const(polarity), value=term.value, kind=term.kind)
    elif term.op in ("and", "or"):
        result = f.op(term.op, *(eased(f, a, polarity, memo) for a in term.args), kind=term.kind)
    elif term.op == "not":
        result = f.op("not", eased(f, term.args[0], -polarity, memo), kind=term.kind)
    else:
        result = term
    memo[key] = result
    return result
