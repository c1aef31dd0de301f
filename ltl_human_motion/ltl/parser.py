"""Parser for the LTL grammar of Sec. II-A, in the paper's notation and Spot's ASCII syntax.

Accepted tokens (either column):

=========== ===========================================
operator    spellings
=========== ===========================================
not         ``!`` ``~`` ``¬``
and         ``&`` ``&&`` ``/\\`` ``∧``
or          ``|`` ``||`` ``\\/`` ``∨``
xor         ``xor`` ``^`` ``⊕``
implies     ``->`` ``=>`` ``-->`` ``→``
equivalent  ``<->`` ``<=>`` ``<-->`` ``↔``
next        ``X`` ``()`` ``○``
finally     ``F`` ``<>`` ``◇``
globally    ``G`` ``[]`` ``□``
binary      ``U`` ``R`` ``W`` ``M``
constants   ``true`` ``1`` ``⊤`` / ``false`` ``0`` ``⊥``
=========== ===========================================

Precedence follows the paper (unary operators bind strongest, ``!`` and ``X`` equally;
``U`` binds tighter than ``&``, ``|``, ``->``) and Spot for the rest:
``-> <->`` < ``|`` < ``xor`` < ``&`` < ``U R W M`` < unary. ``->``, ``<->`` and the binary
temporal operators are right associative. As in Spot, a name starting with ``F``, ``G``
or ``X`` directly followed by more letters is read as operators applied to the rest
(``GFp0`` is ``G F p0``); write such a name in double quotes to keep it an atom.

Atoms are task predicates of Table I with their arguments (``carry(O1, R2)``), the region
atom ``enter(R)``, shorthands defined by the cell (expanded in place), or, with
``free_atoms=True``, plain propositions such as ``p0``. A quoted atom ``"grasp(O1)"`` is
read like the unquoted predicate.

Input propositions (robot events: ``robot_in(R)``, ``robot_moving``, ``offered(O)`` and
the cell's declared ``inputs``) are read only with ``reactive=True`` (a GR(1)
specification, docs/reactive.md); elsewhere, and in a shorthand's body, an input is
refused at its position, since the worker cannot do it as a task.
"""

from __future__ import annotations

from dataclasses import dataclass

from ltl_human_motion.errors import SpecError, did_you_mean
from ltl_human_motion.ltl.formula import (
    FALSE,
    TRUE,
    And,
    Atom,
    Equiv,
    Finally,
    Formula,
    Globally,
    Implies,
    Next,
    Not,
    Or,
    Release,
    StrongRelease,
    Until,
    WeakUntil,
    Xor,
)
from ltl_human_motion.ltl.limits import MAX_NESTING, MAX_SPEC_CHARS, check_formula_limits
from ltl_human_motion.ltl.vocabulary import Vocabulary, vocabulary_from
from ltl_human_motion.vocabulary import INPUT_ARGUMENTS, REGION_ATOM, TASK_ARGUMENTS

__all__ = ["ParsedSpec", "parse", "parse_spec"]

_MAX_SHORTHAND_DEPTH = 8

# (spelling, kind, value), longest spellings first
_SYMBOLS: list[tuple[str, str, str]] = sorted([
    ("<-->", "bin", "<->"), ("<=>", "bin", "<->"), ("<->", "bin", "<->"), ("↔", "bin", "<->"),
    ("-->", "bin", "->"), ("->", "bin", "->"), ("=>", "bin", "->"), ("→", "bin", "->"),
    ("&&", "bin", "&"), ("/\\", "bin", "&"), ("&", "bin", "&"), ("∧", "bin", "&"),
    ("||", "bin", "|"), ("\\/", "bin", "|"), ("|", "bin", "|"), ("∨", "bin", "|"),
    ("^", "bin", "xor"), ("⊕", "bin", "xor"),
    ("!", "un", "!"), ("~", "un", "!"), ("¬", "un", "!"),
    ("[]", "un", "G"), ("□", "un", "G"), ("<>", "un", "F"), ("◇", "un", "F"),
    ("○", "un", "X"),
    ("⊤", "const", "1"), ("⊥", "const", "0"),
    ("(", "(", "("), (")", ")", ")"), (",", ",", ","),
], key=lambda s: -len(s[0]))

_WORD_BINARY = {"U": "U", "R": "R", "W": "W", "M": "M", "V": "R", "xor": "xor"}
_WORD_CONST = {"true": "1", "TRUE": "1", "false": "0", "FALSE": "0"}
_PRECEDENCE = {"->": (1, True), "<->": (1, True), "|": (2, False), "xor": (3, False),
               "&": (4, False), "U": (5, True), "R": (5, True), "W": (5, True),
               "M": (5, True)}
_BINARY_CLASS = {"->": Implies, "<->": Equiv, "xor": Xor, "U": Until, "R": Release,
                 "W": WeakUntil, "M": StrongRelease}
_UNARY_CLASS = {"!": Not, "X": Next, "F": Finally, "G": Globally}
_KIND_WORD = {"object": "an object", "region": "a region", "duration": "a number"}


@dataclass(frozen=True)
class _Token:
    kind: str  # bin un const ( ) , ident string number eof
    value: str
    pos: int


@dataclass(frozen=True)
class ParsedSpec:
    """A parsed specification.

    Attributes
    ----------
    text : str
        The source text.
    formula : Formula
        The formula with shorthands expanded.
    tasks : tuple of Atom
        Task atoms and shorthand instances written in the text, in order of first
        appearance (the candidate task steps of this specification).
    inputs : tuple of Atom
        Input propositions written in the text, in order of first appearance (only with
        ``reactive=True``).
    """

    text: str
    formula: Formula
    tasks: tuple[Atom, ...]
    inputs: tuple[Atom, ...] = ()


def _is_ident_start(ch: str) -> bool:
    return ch.isalpha() or ch == "_"


def _is_ident_char(ch: str) -> bool:
    return ch.isalnum() or ch in "_."


class _Lexer:
    def __init__(self, text: str) -> None:
        self.text = text

    def error(self, message: str, pos: int) -> SpecError:
        return _error(self.text, message, pos)

    def tokens(self) -> list[_Token]:
        text, i, out = self.text, 0, []
        n = len(text)
        in_args = False
        while i < n:
            ch = text[i]
            if ch.isspace():
                i += 1
                continue
            if ch == '"':
                j, buf = i + 1, []
                while j < n and text[j] != '"':
                    if text[j] == "\\" and j + 1 < n:
                        j += 1
                    buf.append(text[j])
                    j += 1
                if j >= n:
                    raise self.error("unterminated quoted atom; expected a closing '\"'", i)
                out.append(_Token("string", "".join(buf), i))
                i = j + 1
                continue
            if _is_ident_start(ch):
                j = i
                while j < n and _is_ident_char(text[j]):
                    j += 1
                if in_args:  # arguments are names, never operators
                    out.append(_Token("ident", text[i:j], i))
                else:
                    self._word(text[i:j], i, j, out)
                    in_args = out[-1].kind == "ident" and self._calls(j)
                i = j
                continue
            if ch.isdigit():
                j = i
                while j < n and (text[j].isdigit() or text[j] in ".eE" or
                                 (text[j] in "+-" and text[j - 1] in "eE")):
                    j += 1
                out.append(_Token("number", text[i:j], i))
                i = j
                continue
            for spelling, kind, value in _SYMBOLS:
                if text.startswith(spelling, i):
                    if kind == ")" or (in_args and kind not in ("(", ",")):
                        in_args = False
                    out.append(_Token(kind, value, i))
                    i += len(spelling)
                    break
            else:
                raise self.error(f"unexpected character {ch!r}; expected an atom, an "
                                 "operator or a parenthesis", i)
        out.append(_Token("eof", "", n))
        return out

    def _word(self, word: str, start: int, end: int, out: list[_Token]) -> None:
        if word in _WORD_BINARY:
            out.append(_Token("bin", _WORD_BINARY[word], start))
        elif word in _WORD_CONST:
            out.append(_Token("const", _WORD_CONST[word], start))
        elif word[0] in "FGX" and (set(word) <= set("FGX") or not self._calls(end)):
            # Spot's rule: leading F/G/X letters are operators (GFp0 = G F p0)
            k = 0
            while k < len(word) and word[k] in "FGX":
                out.append(_Token("un", word[k], start + k))
                k += 1
            if k < len(word):
                rest = word[k:]
                if rest in _WORD_CONST:
                    out.append(_Token("const", _WORD_CONST[rest], start + k))
                elif rest[0].isdigit():
                    out.append(_Token("number", rest, start + k))
                else:
                    out.append(_Token("ident", rest, start + k))
        else:
            out.append(_Token("ident", word, start))

    def _calls(self, end: int) -> bool:
        """True if the word ending at ``end`` is followed by '(' (a predicate call)."""
        rest = self.text[end:].lstrip()
        return rest.startswith("(") and not rest.startswith("()")


def _error(text: str, message: str, pos: int) -> SpecError:
    line = text.count("\n", 0, pos) + 1
    column = pos - (text.rfind("\n", 0, pos) + 1) + 1
    return SpecError(message, text=text, line=line, column=column)


class _Parser:
    def __init__(self, text: str, vocab: Vocabulary, free_atoms: bool,
                 bindings: dict[str, str] | None = None, depth: int = 0,
                 reactive: bool = False) -> None:
        self.text = text
        self.vocab = vocab
        self.free_atoms = free_atoms
        self.bindings = bindings or {}
        self.depth = depth
        self.reactive = reactive
        self.toks = _Lexer(text).tokens()
        self.i = 0
        self.tasks: list[Atom] = []
        self.inputs: list[Atom] = []

    # ---------------------------------------------------------------- token helpers
    def peek(self) -> _Token:
        return self.toks[self.i]

    def advance(self) -> _Token:
        tok = self.toks[self.i]
        self.i += 1
        return tok

    def error(self, message: str, pos: int) -> SpecError:
        return _error(self.text, message, pos)

    def describe(self, tok: _Token) -> str:
        if tok.kind == "eof":
            return "end of the specification"
        if tok.kind == "string":
            return f'"{tok.value}"'
        return repr(self.text[tok.pos:tok.pos + max(len(tok.value), 1)]) \
            if tok.kind in ("bin", "un") else repr(tok.value)

    # ---------------------------------------------------------------- grammar
    def parse(self) -> Formula:
        if self.peek().kind == "eof":
            raise self.error("empty specification; expected an LTL formula", 0)
        f = self.expression(0)
        tok = self.peek()
        if tok.kind != "eof":
            if tok.kind == ")":
                raise self.error("unbalanced ')'; expected an operator or the end", tok.pos)
            raise self.error(f"unexpected {self.describe(tok)}; expected a binary operator "
                             "(&, |, ->, <->, U, R, W, M) or the end", tok.pos)
        return f

    def expression(self, min_prec: int) -> Formula:
        left = self.unary()
        while True:
            tok = self.peek()
            if tok.kind != "bin":
                return left
            prec, right_assoc = _PRECEDENCE[tok.value]
            if prec < min_prec:
                return left
            op = tok.value
            if op in ("&", "|"):
                operands = [left]
                while self.peek().kind == "bin" and self.peek().value == op:
                    self.advance()
                    operands.append(self.expression(prec + 1))
                left = (And if op == "&" else Or)(tuple(operands))
                continue
            self.advance()
            right = self.expression(prec if right_assoc else prec + 1)
            left = _BINARY_CLASS[op](left, right)

    def unary(self) -> Formula:
        tok = self.advance()
        if tok.kind == "un":
            return _UNARY_CLASS[tok.value](self.unary())
        if tok.kind == "(":
            if self.peek().kind == ")":  # "()" is Spot's next operator
                self.advance()
                return Next(self.unary())
            inner = self.expression(0)
            close = self.advance()
            if close.kind == "eof":
                raise self.error(f"expected ')' to close the '(' at column "
                                 f"{self._column(tok.pos)} before the end of the "
                                 "specification", close.pos)
            if close.kind != ")":
                raise self.error(f"expected ')' to close the '(' at column "
                                 f"{self._column(tok.pos)}, found {self.describe(close)}",
                                 close.pos)
            return inner
        if tok.kind == "const":
            return TRUE if tok.value == "1" else FALSE
        if tok.kind == "number" and tok.value in ("0", "1"):
            return TRUE if tok.value == "1" else FALSE
        if tok.kind == "number":
            raise self.error(f"unexpected number {tok.value!r}; numbers are only task "
                             "arguments such as wait(2.0)", tok.pos)
        if tok.kind == "ident":
            return self.predicate(tok)
        if tok.kind == "string":
            return self.quoted(tok)
        what = self.describe(tok)
        raise self.error(f"unexpected {what}; expected an atom, '!', 'X', 'F', 'G', "
                         "a constant or '('", tok.pos)

    def _column(self, pos: int) -> int:
        return pos - (self.text.rfind("\n", 0, pos) + 1) + 1

    # ---------------------------------------------------------------- atoms
    def quoted(self, tok: _Token) -> Formula:
        inner = tok.value.strip()
        try:
            sub = _Parser(inner, self.vocab, self.free_atoms, self.bindings, self.depth,
                          self.reactive)
            name_tok = sub.advance()
            if name_tok.kind == "ident" and sub.toks[-1].kind == "eof":
                f = sub.predicate(name_tok)
                if sub.peek().kind == "eof":
                    self.tasks.extend(t for t in sub.tasks if t not in self.tasks)
                    self.inputs.extend(t for t in sub.inputs if t not in self.inputs)
                    return f
        except SpecError as exc:
            if self.vocab.objects is not None or not self.free_atoms:
                raise self.error(f'in quoted atom "{tok.value}": {exc.message}',
                                 tok.pos) from None
        if not self.free_atoms:
            raise self.error(f'"{tok.value}" is not a task predicate; expected e.g. '
                             '"grasp(O1)"', tok.pos)
        return Atom(tok.value)

    def arguments(self) -> list[_Token]:
        self.advance()  # "("
        args: list[_Token] = []
        if self.peek().kind == ")":
            self.advance()
            return args
        while True:
            tok = self.advance()
            if tok.kind not in ("ident", "number"):
                raise self.error(f"unexpected {self.describe(tok)}; expected an argument "
                                 "(an object, a region or a number)", tok.pos)
            args.append(tok)
            sep = self.advance()
            if sep.kind == ")":
                return args
            if sep.kind != ",":
                raise self.error(f"unexpected {self.describe(sep)}; expected ',' or ')' in "
                                 "the argument list", sep.pos)

    def predicate(self, tok: _Token) -> Formula:
        name = tok.value
        has_call = self.peek().kind == "("
        arg_toks = self.arguments() if has_call else []
        if name in self.bindings and not has_call:
            raise self.error(f"parameter '{name}' used as a formula; expected a task", tok.pos)
        args = [self.bindings.get(a.value, a.value) for a in arg_toks]
        if name in self.vocab.shorthands:
            return self.shorthand(tok, args, arg_toks)
        if name in TASK_ARGUMENTS or name == REGION_ATOM:
            atom = self.typed_atom(tok, "task", TASK_ARGUMENTS.get(name, ("region",)), args,
                                   arg_toks)
            if name != REGION_ATOM and atom not in self.tasks:
                self.tasks.append(atom)
            return atom
        if name in INPUT_ARGUMENTS or name in self.vocab.inputs:
            return self.input_atom(tok, args, arg_toks)
        if self.free_atoms:
            return Atom(name, tuple(args))
        known = sorted(set(TASK_ARGUMENTS) | {REGION_ATOM} | set(self.vocab.shorthands))
        raise self.error(f"unknown task '{name}'; {did_you_mean(name, known)}expected one of: "
                         f"{', '.join(known)}", tok.pos)

    def input_atom(self, tok: _Token, args: list[str], arg_toks: list[_Token]) -> Atom:
        name = tok.value
        if not self.reactive:
            where = " in the body of a shorthand" if self.depth else ""
            raise self.error(f"'{name}' is an input (a robot or cell event the worker "
                             f"observes), not a task the worker can do{where}; inputs "
                             "belong in a reactive specification "
                             "(assumptions -> guarantees, `ltl-human-motion react`)", tok.pos)
        atom = self.typed_atom(tok, "input", INPUT_ARGUMENTS.get(name, ()), args, arg_toks)
        if atom not in self.inputs:
            self.inputs.append(atom)
        return atom

    def typed_atom(self, tok: _Token, what: str, kinds: tuple[str, ...], args: list[str],
                   arg_toks: list[_Token]) -> Atom:
        """The atom ``tok(args)`` with its arguments checked against ``kinds``."""
        name = tok.value
        if len(args) != len(kinds):
            wanted = ", ".join(kinds) if kinds else "no arguments"
            raise self.error(f"{what} '{name}' takes {len(kinds)} argument"
                             f"{'' if len(kinds) == 1 else 's'} ({wanted}), got "
                             f"{len(args)}", tok.pos)
        return Atom(name, tuple(self.check_arg(a, t, kind, name)
                                for a, t, kind in zip(args, arg_toks, kinds)))

    def check_arg(self, value: str, tok: _Token, kind: str, task: str) -> str:
        if kind == "duration":
            try:
                number = float(value)
            except ValueError:
                raise self.error(f"task '{task}' expects a number (seconds), got "
                                 f"'{value}'", tok.pos) from None
            if not number >= 0 or number == float("inf"):
                raise self.error(f"task '{task}' expects a finite duration >= 0, got "
                                 f"'{value}'", tok.pos)
            return repr(number)
        if tok.kind == "number" and value == tok.value:
            raise self.error(f"task '{task}' expects {_KIND_WORD[kind]} name, got the "
                             f"number '{value}'", tok.pos)
        names = self.vocab.objects if kind == "object" else self.vocab.regions
        if names is not None and value not in names:
            listed = ", ".join(sorted(names)) or "(none)"
            raise self.error(f"unknown {kind} '{value}' in task '{task}'; "
                             f"{did_you_mean(value, names)}expected one of the cell's {kind}s: "
                             f"{listed}", tok.pos)
        return value

    def shorthand(self, tok: _Token, args: list[str], arg_toks: list[_Token]) -> Formula:
        name = tok.value
        params, body = self.vocab.shorthands[name]
        if len(args) != len(params):
            raise self.error(f"shorthand '{name}' takes {len(params)} argument"
                             f"{'' if len(params) == 1 else 's'} ({', '.join(params)}), "
                             f"got {len(args)}", tok.pos)
        if self.depth >= _MAX_SHORTHAND_DEPTH:
            raise self.error(f"shorthand '{name}' expands too deeply (recursive "
                             "definition?)", tok.pos)
        known = None
        if self.vocab.objects is not None:
            known = set(self.vocab.objects) | set(self.vocab.regions or ())
        for value, arg_tok in zip(args, arg_toks):
            if known is not None and value not in known and arg_tok.kind != "number":
                raise self.error(f"unknown argument '{value}' of shorthand '{name}'; "
                                 f"expected an object or region of the cell: "
                                 f"{', '.join(sorted(known))}", arg_tok.pos)
        sub = _Parser(body, self.vocab, self.free_atoms, dict(zip(params, args)),
                      self.depth + 1)
        try:
            formula = sub.parse()
        except SpecError as exc:
            raise self.error(f"in shorthand {name}({', '.join(params)}) = {body!r}: "
                             f"{exc.message}", tok.pos) from None
        instance = Atom(name, tuple(args))
        if instance not in self.tasks:
            self.tasks.append(instance)
        return formula


def parse_spec(text: str, cell: object = None, *, free_atoms: bool = False,
               reactive: bool = False) -> ParsedSpec:
    """Parse ``text`` and report the task steps it mentions.

    Parameters
    ----------
    text : str
        The specification.
    cell : CellVocabulary, dict, path or None
        Objects, regions and shorthands; None checks task names and arities only.
    free_atoms : bool
        Accept unknown names as plain propositions (``p0``) instead of raising.
    reactive : bool
        Accept input propositions (robot events; :attr:`ParsedSpec.inputs`). Without it
        an input is refused at its position.

    Returns
    -------
    ParsedSpec

    Raises
    ------
    SpecError
        With line, column and what was expected, for any malformed or ill-typed input.
    """
    if not isinstance(text, str):
        raise SpecError(f"a specification must be a string, got {type(text).__name__}")
    if len(text) > MAX_SPEC_CHARS:
        raise SpecError(f"the specification has {len(text)} characters; at most "
                        f"{MAX_SPEC_CHARS} are allowed (MAX_SPEC_CHARS)")
    vocab = vocabulary_from(cell)
    parser = _Parser(text, vocab, free_atoms, reactive=reactive)
    try:
        formula = parser.parse()
    except RecursionError:
        raise SpecError(f"the specification nests operators deeper than {MAX_NESTING} "
                        "(MAX_NESTING)", text=text) from None
    check_formula_limits(formula, text)
    return ParsedSpec(text=text, formula=formula, tasks=tuple(parser.tasks),
                      inputs=tuple(parser.inputs))


def parse(text: str, cell: object = None, *, free_atoms: bool = False,
          reactive: bool = False) -> Formula:
    """Parse an LTL specification into a :class:`Formula` (see :func:`parse_spec`)."""
    return parse_spec(text, cell, free_atoms=free_atoms, reactive=reactive).formula
