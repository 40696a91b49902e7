"""Parsing SpREs the way STREM v0.2.0 does (``--compat strem``).

STREM's hand-written grammar gives every binary operator at every level equal
precedence and right associativity: each operator takes "the whole rest" as its
right operand (docs/strem-reference.md §3)::

    spre  := prim post* [ spre | '|' spre ]        prim := '(' spre ')' | '[' s4u ']'
    post  := '*' | '{' INT '}' | '{' INT ',' '}' | '{' INT ',' INT '}'
    s4u   := ( '(' s4u ')' | '!' s4u | 'NE' class | 'NE' '(' s4 ')' | 'E' '(' binds ')' s4u
             | 'A' '(' binds ')' s4u | s4m cmp s4m | class ) [ ('&' | '|') s4u ]
    cmp   := '<' | '>' | '<=' | '>='          binds := IDENT ':=' class [ ',' binds ]
    s4m   := ( '(' s4m ')' | '@' IDENT '(' s4 [ ',' s4 ] ')' | REAL | INT | '-' s4m ) [ ('+'|'-'|'*'|'/') s4m ]
    s4    := ( '(' s4 ')' | IDENT | '!' s4 | class ) [ ('&' | '|') s4 ]
    class := '[' ':' IDENT ':' ']'

So ``AB|C`` is A(B|C), ``a & b | c`` is a & (b | c), ``a - b - c`` is a - (b - c), and ``!``,
``E(..)`` and ``A(..)`` scope over the rest of the formula. The result is the same syntax
tree type as scenegrep's parser produces.
"""

from __future__ import annotations

from . import syntax as s
from .errors import query_error
from .tokens import Cursor, Token, nested, tokenize_strem


class StremParser(Cursor):
    """A recursive-descent parser of STREM's grammar over STREM's tokens."""

    def __init__(self, text: str, source: str = "<query>"):
        tokens, self.warnings = tokenize_strem(text, source)
        super().__init__(text, source, tokens)

    def at_keyword(self, word: str) -> bool:
        return self.token.kind == "KEYWORD" and self.token.text == word

    # ------------------------------------------------------------------ regex layer
    def parse(self) -> s.Query:
        if self.at("END"):
            return s.Empty((0, 0))
        query = self.spre()
        if not self.at("END"):
            raise self.error(f"syntax error: unexpected {self.token.text!r}")
        return query

    @nested
    def spre(self) -> s.Query:
        start = self.token
        item = self.prim()
        while self.at("*", "{"):
            item = self.post(item, start)
        if self.at("|"):
            self.take()
            return s.Alternation((item, self.spre()), self.span(start))
        if self.at("(", "["):
            return s.Concat((item, self.spre()), self.span(start))
        return item

    def post(self, item: s.Query, start: Token) -> s.Query:
        brace = self.take()
        if brace.kind == "*":
            return s.Repeat(item, 0, None, self.span(start))
        low = self.count("an integer")
        high: int | None = low
        if self.at(","):
            self.take()
            high = self.count() if self.at("INT") else None
        close = self.expect("}", "'}'")
        if high is not None and low > high:
            raise query_error(
                f"repetition {{{low},{high}}} has its minimum above its maximum (STREM panics here)",
                self.text,
                brace.start,
                close.end,
                self.source,
            )
        return s.Repeat(item, low, high, self.span(start))

    def prim(self) -> s.Query:
        start = self.token
        if self.at("("):
            self.take()
            query = self.spre()
            self.expect(")", "')'")
            return query
        self.expect("[", "'[' or '('")
        formula = self.s4u()
        self.expect("]", "']'")
        return s.Letter(formula, self.span(start))

    # ------------------------------------------------------------------ spatial formulas
    @nested
    def s4u(self) -> s.Formula:
        start = self.token
        head = self.s4u_head()
        if self.at("&", "|"):
            op = self.take().text
            node = s.And if op == "&" else s.Or
            return node(head, self.s4u(), self.span(start))
        return head

    def s4u_head(self) -> s.Formula:
        start = self.token
        if self.at("("):
            self.take()
            inner = self.s4u()
            self.expect(")", "')'")
            return inner
        if self.at("!"):
            self.take()
            return s.Not(self.s4u(), self.span(start))
        if self.at_keyword("NE"):
            self.take()
            if self.at("("):
                self.take()
                term = self.s4()
                self.expect(")", "')'")
            else:
                term = self.class_atom()
            return s.NonEmpty(term, self.span(start))
        if self.at_keyword("E") or self.at_keyword("A"):
            kind = self.take().text
            self.expect("(", "'('")
            bindings = self.binds()
            self.expect(")", "')'")
            return s.Quantifier(kind, bindings, self.s4u(), self.span(start))
        if self.at("[") and self.tokens[self.pos + 1].kind == ":":
            atom = self.class_atom()
            return s.Present(atom, atom.span)
        if self.at("@", "INT", "REAL", "-"):
            left = self.s4m()
            if not self.at("<", ">", "<=", ">="):
                raise self.error("expected a comparison < > <= >=")
            op = self.take().text
            return s.Compare(op, left, self.s4m(), self.span(start))
        raise self.error("syntax error")

    @nested
    def binds(self) -> tuple[s.Binding, ...]:
        start = self.token
        name = self.expect("IDENT", "a variable").text
        self.expect(":=", "':='")
        binding = s.Binding(name, self.class_atom(), self.span(start))
        if self.at(","):
            self.take()
            return (binding, *self.binds())
        return (binding,)

    # ------------------------------------------------------------------ metric expressions
    @nested
    def s4m(self) -> s.Metric:
        start = self.token
        head = self.s4m_head()
        if self.at("+", "-", "*", "/"):
            op = self.take().text
            return s.Arithmetic(op, head, self.s4m(), self.span(start))
        return head

    def s4m_head(self) -> s.Metric:
        start = self.token
        if self.at("("):
            self.take()
            inner = self.s4m()
            self.expect(")", "')'")
            return inner
        if self.at("-"):
            self.take()
            return s.Negate(self.s4m(), self.span(start))
        if self.at("INT", "REAL"):
            return s.Number(float(self.take().text), self.span(start))
        if self.at("@"):
            self.take()
            name = self.expect("IDENT", "a function name").text
            self.expect("(", "'('")
            args = [self.s4()]
            if self.at(","):
                self.take()
                args.append(self.s4())
            self.expect(")", "')'")
            return s.Function(name, tuple(args), self.span(start))
        raise self.error("syntax error")

    # ------------------------------------------------------------------ spatial terms
    @nested
    def s4(self) -> s.Term:
        start = self.token
        head = self.s4_head()
        if self.at("&", "|"):
            op = self.take().text
            node = s.Intersection if op == "&" else s.Union
            return node(head, self.s4(), self.span(start))
        return head

    def s4_head(self) -> s.Term:
        start = self.token
        if self.at("("):
            self.take()
            inner = self.s4()
            self.expect(")", "')'")
            return inner
        if self.at("!"):
            self.take()
            return s.Complement(self.s4(), self.span(start))
        if self.at("IDENT"):
            return s.Var(self.take().text, self.span(start))
        return self.class_atom()

    def class_atom(self) -> s.ClassAtom:
        start = self.expect("[", "'['")
        self.expect(":", "':'")
        name = self.expect("IDENT", "a class name").text
        self.expect(":", "':'")
        self.expect("]", "']'")
        return s.ClassAtom(name, (), self.span(start))


def parse_strem(text: str, source: str = "<query>") -> tuple[s.Query, list[str]]:
    """The syntax tree of a query in STREM v0.2.0's syntax, and the lexer's warnings."""
    parser = StremParser(text, source)
    return parser.parse(), parser.warnings
