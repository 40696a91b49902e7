"""Parsing scenegrep's SpRE syntax: STREM's notation with standard precedence, plus the
paper's notation and scenegrep's extensions.

Grammar (lowest precedence first; ``|`` in quotes is the operator)::

    query     := concat ( '|' concat )*                      (empty text: the empty query)
    concat    := repeat+
    repeat    := primary ( '*' | '+' | '?' | '{' m '}' | '{' m ',' '}' | '{' m ',' n '}' | '{' ',' n '}' )*
    primary   := '[' formula ']' | class | '(' query ')' | '.' | 'E' '(' binding ')' primary
    formula   := and ( '|' and )*
    and       := unary ( '&' unary )*
    unary     := ( '!' | '~' ) unary | ( 'E' | 'A' | '<exists>' | '<forall>' ) '(' bindings ')' unary | atom
    atom      := '(' formula ')' | ( 'NE' | '<nonempty>' ) tunary | relation '(' term [ ',' term ] ')'
               | operand [ cmp operand ] | operand ( '<subset>' | '<=' ) operand
    operand   := metric | tunary                            (a bare term is "present")
    cmp       := '<' | '>' | '<=' | '>=' | '==' | '!='
    metric    := product ( ( '+' | '-' ) product )*
    product   := signed ( ( '*' | '/' ) signed )*
    signed    := '-' signed | power          power := mprimary [ '^' signed ]
    mprimary  := number | ( '@' name | '<' name '>' ) '(' term ( ',' term )* ')' | '(' metric ')'
    term      := tand ( '|' tand )*          tand := tunary ( '&' tunary )*
    tunary    := ( '!' | '~' ) tunary | ( 'I' | 'C' ) '(' term ')' | ( '<interior>' | '<closure>' ) tunary | tprimary
    tprimary  := class | variable | '(' term ')'
    class     := '[' ':' name [ ':' filter ( ',' filter )* ] ':' ']'    (name: identifier with . and -, "quoted", or *)
    filter    := key ( '=' | '!=' | '<' | '<=' | '>' | '>=' ) value

Inside ``[...]`` the operators ``& | !`` are the logical and, or, not of formulas; inside
``NE(...)``, function arguments and other terms they are region intersection, union and
complement. The body of a quantifier is the formula right after it (parenthesise more).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, TypeVar

from ..errors import UserError
from . import syntax as s
from .errors import query_error
from .tokens import Cursor, Token, TooDeep, nested, tokenize, unquote

T = TypeVar("T")

COMPARISONS = ("<", ">", "<=", ">=", "==", "!=")
RELATIONS = ("frontof", "behind", "leftof", "rightof", "above", "below")
ANGLE_FUNCTIONS = ("x", "y", "z", "dist", "area", "width", "height", "gap", "iou", "score", "speed")
FILTER_OPS = ("=", "!=", "<", "<=", ">", ">=")


class _Backtrack(Exception):
    """Raised inside a tentative parse; the caller rewinds and tries another reading."""


class Parser(Cursor):
    """A recursive-descent parser over the tokens of one query text."""

    def __init__(self, text: str, source: str = "<query>"):
        super().__init__(text, source, tokenize(text, source))

    def at_word(self, *words: str) -> bool:
        return self.token.kind == "IDENT" and self.token.text in words

    def attempt(self, parse: Callable[[], T]) -> T | None:
        """Run ``parse``; on a syntax error rewind and return None."""
        saved = self.pos
        try:
            return parse()
        except TooDeep:
            raise
        except (UserError, _Backtrack):
            self.pos = saved
            return None

    # ------------------------------------------------------------------ queries
    def parse(self) -> s.Query:
        if self.at("END"):
            return s.Empty((0, 0))
        query = self.alternation()
        if not self.at("END"):
            raise self.error(f"unexpected {self.token.text!r} (expected '|', a frame formula or the end)")
        return query

    def alternation(self) -> s.Query:
        start = self.token
        options = [self.concat()]
        while self.at("|"):
            self.take()
            options.append(self.concat())
        return options[0] if len(options) == 1 else s.Alternation(tuple(options), self.span(start))

    def starts_primary(self) -> bool:
        return self.at("[", "(", ".") or (self.at_word("E") and self.tokens[self.pos + 1].kind == "(")

    def concat(self) -> s.Query:
        start = self.token
        items = []
        while self.starts_primary():
            items.append(self.repeat())
        if not items:
            raise self.error("expected a frame formula '[...]', '(', '.' or 'E(...)'")
        return items[0] if len(items) == 1 else s.Concat(tuple(items), self.span(start))

    def repeat(self) -> s.Query:
        start = self.token
        item = self.primary()
        while self.at("*", "+", "?", "{"):
            op = self.take()
            if op.kind == "{":
                low, high = self.bounds(op)
            else:
                low, high = {"*": (0, None), "+": (1, None), "?": (0, 1)}[op.kind]
            item = s.Repeat(item, low, high, self.span(start))
        return item

    def bounds(self, brace: Token) -> tuple[int, int | None]:
        low = self.count() if self.at("INT") else None
        high: int | None
        if self.at(","):
            self.take()
            high = self.count() if self.at("INT") else None
        else:
            high = low
        close = self.expect("}", "'}' closing the repetition")
        if low is None and high is None:
            raise query_error(
                "a repetition needs a count: {m}, {m,}, {m,n} or {,n}", self.text, brace.start, close.end, self.source
            )
        low = low or 0
        if high is not None and low > high:
            raise query_error(
                f"repetition {{{low},{high}}} has its minimum above its maximum",
                self.text,
                brace.start,
                close.end,
                self.source,
            )
        return low, high

    @nested
    def primary(self) -> s.Query:
        start = self.token
        if self.at("."):
            self.take()
            return s.AnyFrame(self.span(start))
        if self.at("("):
            self.take()
            query = self.alternation()
            self.expect(")", "')' closing the group")
            return query
        if self.at_word("E"):
            self.take()
            self.expect("(", "'(' after E")
            binding = self.binding()
            self.expect(")", "')' closing the track binding")
            return s.TrackBinder(binding, self.primary(), self.span(start))
        if self.tokens[self.pos + 1].kind == ":":
            atom = self.class_atom()
            return s.Letter(s.Present(atom, atom.span), atom.span)
        self.expect("[", "'['")
        if self.at("]"):
            raise self.error("empty frame formula '[]'")
        formula = self.formula()
        self.expect("]", "']' closing the frame formula")
        return s.Letter(formula, self.span(start))

    # ------------------------------------------------------------------ formulas
    def formula(self) -> s.Formula:
        return self.chain("|", s.Or, self.conjunction)

    def conjunction(self) -> s.Formula:
        return self.chain("&", s.And, self.unary)

    def chain(self, op: str, node: type, operand: Callable[[], T]) -> T:
        """Operands separated by the associative operator ``op``, joined by ``node`` as a balanced
        tree: a chain of thousands of operands nests only log2 of their number deep."""
        start = self.token
        items = [operand()]
        while self.at(op):
            self.take()
            items.append(operand())
        return _balanced(node, items, self.span(start))

    @nested
    def unary(self) -> s.Formula:
        start = self.token
        if self.at("!", "~"):
            self.take()
            return s.Not(self.unary(), self.span(start))
        if (self.at_word("E", "A") and self.tokens[self.pos + 1].kind == "(") or self.at_angle("exists", "forall"):
            kind = "E" if self.take().text in ("E", "<exists>") else "A"
            self.expect("(", "'(' opening the quantifier's bindings")
            bindings = [self.binding()]
            while self.at(","):
                self.take()
                bindings.append(self.binding())
            self.expect(")", "')' closing the quantifier's bindings")
            return s.Quantifier(kind, tuple(bindings), self.unary(), self.span(start))
        return self.atom()

    def at_angle(self, *names: str) -> bool:
        return self.token.kind == "ANGLE" and self.token.text[1:-1] in names

    def binding(self) -> s.Binding:
        start = self.token
        name = self.expect("IDENT", "a variable name").text
        self.expect(":=", "':='")
        return s.Binding(name, self.class_atom(), self.span(start))

    def atom(self) -> s.Formula:
        start = self.token
        if self.at("("):
            grouped = self.attempt(self.grouped_formula)
            if grouped is not None:
                return grouped
        if self.at_word("NE") or self.at_angle("nonempty"):
            self.take()
            return s.NonEmpty(self.term_unary(), self.span(start))
        if self.at_angle(*RELATIONS):
            name = self.take().text[1:-1]
            self.expect("(", f"'(' after <{name}>")
            left = self.term()
            right = None
            if self.at(","):
                self.take()
                right = self.term()
            self.expect(")", f"')' closing <{name}>")
            return s.Relation(name, left, right, self.span(start))
        left = self.operand()
        if self.at_angle("subset") or (self.at("<=") and not _is_metric(left)):
            op = self.take()
            right = self.operand()
            if _is_metric(left) or _is_metric(right):
                raise self.error("<subset> compares region sets, not numbers", op)
            return s.Subset(left, right, self.span(start))
        if self.at(*COMPARISONS):
            op = self.take()
            right = self.operand()
            if not (_is_metric(left) and _is_metric(right)):
                raise self.error(f"{op.text!r} compares numbers; wrap regions in a function such as @area(...)", op)
            return s.Compare(op.text, left, right, self.span(start))
        if _is_metric(left):
            raise self.error("a number is not a formula: compare it with < > <= >= == !=")
        return s.Present(left, self.span(start))

    def grouped_formula(self) -> s.Formula:
        self.take()
        inner = self.formula()
        self.expect(")", "')'")
        if self.at(*COMPARISONS, "+", "-", "*", "/", "^") or self.at_angle("subset"):
            raise _Backtrack()
        return inner

    def operand(self) -> s.Metric | s.Term:
        if self.at("INT", "REAL", "-", "@") or self.at_angle(*ANGLE_FUNCTIONS):
            return self.metric()
        if self.at("("):
            metric = self.attempt(self.metric)
            if metric is not None:
                return metric
        return self.term_unary()

    # ------------------------------------------------------------------ metric expressions
    def metric(self) -> s.Metric:
        start = self.token
        left = self.product()
        while self.at("+", "-"):
            op = self.take().text
            left = s.Arithmetic(op, left, self.product(), self.span(start))
        return left

    def product(self) -> s.Metric:
        start = self.token
        left = self.signed()
        while self.at("*", "/"):
            op = self.take().text
            left = s.Arithmetic(op, left, self.signed(), self.span(start))
        return left

    @nested
    def signed(self) -> s.Metric:
        start = self.token
        if self.at("-"):
            self.take()
            return s.Negate(self.signed(), self.span(start))
        base = self.metric_primary()
        if self.at("^"):
            self.take()
            return s.Arithmetic("^", base, self.signed(), self.span(start))
        return base

    def metric_primary(self) -> s.Metric:
        start = self.token
        if self.at("INT", "REAL"):
            return s.Number(float(self.take().text), self.span(start))
        if self.at("@") or self.at_angle(*ANGLE_FUNCTIONS):
            name = self.take().text[1:-1] if self.at("ANGLE") else self.take_function_name()
            self.expect("(", f"'(' after the function {name!r}")
            args = [self.term()]
            while self.at(","):
                self.take()
                args.append(self.term())
            self.expect(")", f"')' closing the arguments of {name!r}")
            return s.Function(name, tuple(args), self.span(start))
        if self.at("("):
            self.take()
            inner = self.metric()
            self.expect(")", "')'")
            return inner
        raise self.error("expected a number, a function such as @area(...) or '('")

    def take_function_name(self) -> str:
        self.take()
        return self.expect("IDENT", "a function name after '@'").text

    # ------------------------------------------------------------------ terms
    def term(self) -> s.Term:
        return self.chain("|", s.Union, self.term_intersection)

    def term_intersection(self) -> s.Term:
        return self.chain("&", s.Intersection, self.term_unary)

    @nested
    def term_unary(self) -> s.Term:
        start = self.token
        if self.at("!", "~"):
            self.take()
            return s.Complement(self.term_unary(), self.span(start))
        if self.at_word("I", "C") and self.tokens[self.pos + 1].kind == "(" or self.at_angle("interior", "closure"):
            word = self.take().text
            node = s.Interior if word in ("I", "<interior>") else s.Closure
            return node(self.term_unary(), self.span(start))
        return self.term_primary()

    def term_primary(self) -> s.Term:
        start = self.token
        if self.at("("):
            self.take()
            inner = self.term()
            self.expect(")", "')'")
            return inner
        if self.at("[") and self.tokens[self.pos + 1].kind == ":":
            return self.class_atom()
        if self.at("IDENT") and self.token.text not in ("NE", "E", "A"):
            return s.Var(self.take().text, self.span(start))
        raise self.error("expected a class such as [:car:], a variable or '('")

    def class_atom(self) -> s.ClassAtom:
        start = self.expect("[", "'[:' opening a class")
        self.expect(":", "':' after '['")
        name = self.class_name()
        filters = []
        self.expect(":", "':' after the class name")
        if not self.at("]"):
            filters.append(self.class_filter())
            while self.at(","):
                self.take()
                filters.append(self.class_filter())
            self.expect(":", "':' closing the filters")
        self.expect("]", "']' closing the class")
        return s.ClassAtom(name, tuple(filters), self.span(start))

    def class_name(self) -> str:
        if self.at("*"):
            self.take()
            return "*"
        if self.at("STRING"):
            return unquote(self.take(), self.text, self.source)
        first = self.expect("IDENT", "a class name")
        name, end = first.text, first.end
        while self.at(".", "-") and self.token.start == end and self.tokens[self.pos + 1].kind in ("IDENT", "INT"):
            name += self.take().text + self.token.text
            end = self.take().end
        return name

    def class_filter(self) -> s.Filter:
        key = self.expect("IDENT", "a filter key such as score or colour").text
        if not self.at(*FILTER_OPS):
            raise self.error(f"expected one of {' '.join(FILTER_OPS)} after {key!r}")
        op = self.take().text
        if self.at("INT", "REAL"):
            value: str | float = float(self.take().text)
        elif self.at("-") and self.tokens[self.pos + 1].kind in ("INT", "REAL"):
            self.take()
            value = -float(self.take().text)
        elif self.at("STRING"):
            value = unquote(self.take(), self.text, self.source)
        else:
            value = self.expect("IDENT", "a filter value").text
        return s.Filter(key, op, value)


def _balanced(node: type, items: list, span: s.Span) -> Any:
    """``items`` joined pairwise by ``node`` into a balanced tree spanning ``span`` (left-deep for
    up to three items)."""
    if len(items) == 1:
        return items[0]
    half = (len(items) + 1) // 2
    left = _balanced(node, items[:half], (items[0].span[0], items[half - 1].span[1]))
    right = _balanced(node, items[half:], (items[half].span[0], items[-1].span[1]))
    return node(left, right, span)


def _is_metric(node: object) -> bool:
    return isinstance(node, (s.Number, s.Function, s.Negate, s.Arithmetic))


def parse(text: str, source: str = "<query>") -> s.Query:
    """The syntax tree of a query in scenegrep's syntax; UserError with line:column and a caret."""
    return Parser(text, source).parse()
