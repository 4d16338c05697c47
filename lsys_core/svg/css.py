"""CSS in SVG: ``<style>`` sheets, ``style`` attributes, selectors and their matching.

Tokenising is tinycss2's (a tokenizer after CSS Syntax Level 3): it scans strings and comments
linearly (``str.find`` for comments, one pass for strings), so an unterminated string or comment
of a megabyte ends in one pass instead of a regular expression backtracking; it is small, pure
Python and kept by the WeasyPrint project.  Selectors are read here from tinycss2's tokens
(type, ``*``, ``#id``, ``.class``, attribute selectors, ``:first-child``/``:last-child``,
descendant ``' '``, child ``>``, ``+`` and ``~`` combinators) and matched right to left with
memoisation, so matching work is bounded by selectors × elements × depth; a work counter turns
anything beyond :data:`MAX_MATCH_WORK` steps into a :class:`~lsys_core.errors.LimitError`.
``@import`` (external sheets are never read) and unknown at-rules are skipped, with a note;
the rules after them still apply.
"""

from __future__ import annotations

from collections import defaultdict
from dataclasses import dataclass, field

import tinycss2

from lsys_core.errors import LimitError

__all__ = ["MAX_MATCH_WORK", "Declaration", "StyleSheet", "parse_declarations"]

#: Selector matching steps allowed per document.
MAX_MATCH_WORK = 5_000_000
#: Media types whose rules apply (the drawing is rendered, like on a screen).
_MEDIA_OK = frozenset({"", "all", "screen"})
_COMBINATORS = frozenset({">", "+", "~"})
_ATTR_OPS = frozenset({"=", "~=", "|=", "^=", "$=", "*="})


@dataclass(frozen=True)
class Declaration:
    """One ``name: value [!important]`` declaration (name lower case, value as written)."""

    name: str
    value: str
    important: bool = False


def parse_declarations(text: str) -> list[Declaration]:
    """Read a declaration list (a ``style`` attribute or the block of a rule); invalid parts are skipped."""
    nodes = tinycss2.parse_blocks_contents(text, skip_comments=True, skip_whitespace=True)
    return [_declaration(n) for n in nodes if n.type == "declaration"]


def _declaration(node) -> Declaration:
    return Declaration(node.lower_name, tinycss2.serialize(node.value).strip(), bool(node.important))


@dataclass(frozen=True)
class Compound:
    """A compound selector: optional type, ids, classes, attribute tests and pseudo-classes."""

    tag: str | None = None
    ids: tuple[str, ...] = ()
    classes: tuple[str, ...] = ()
    attrs: tuple[tuple[str, str, str], ...] = ()
    pseudos: tuple[str, ...] = ()


@dataclass(frozen=True)
class Selector:
    """Compounds left to right; ``combinators[i]`` joins ``compounds[i]`` and ``compounds[i + 1]``."""

    compounds: tuple[Compound, ...]
    combinators: tuple[str, ...]

    @property
    def specificity(self) -> tuple[int, int, int]:
        """(ids, classes + attributes + pseudo-classes, types), as CSS counts them."""
        a = sum(len(c.ids) for c in self.compounds)
        b = sum(len(c.classes) + len(c.attrs) + len(c.pseudos) for c in self.compounds)
        c = sum(1 for c in self.compounds if c.tag is not None)
        return (a, b, c)


@dataclass(frozen=True)
class Rule:
    """A selector with its declarations and its place in the document's style sheets."""

    selector: Selector
    specificity: tuple[int, int, int]
    order: int
    declarations: tuple[Declaration, ...]


class _Unsupported(Exception):
    """A selector this reader does not support (the rule never matches, like an invalid one)."""


def _parse_compound(tokens: list, i: int) -> tuple[Compound, int]:
    tag = None
    ids: list[str] = []
    classes: list[str] = []
    attrs: list[tuple[str, str, str]] = []
    pseudos: list[str] = []
    start = i
    while i < len(tokens):
        t = tokens[i]
        if t.type == "ident" and i == start:
            tag = t.value
        elif t.type == "literal" and t.value == "*" and i == start:
            tag = None
        elif t.type == "hash":
            ids.append(t.value)
        elif t.type == "literal" and t.value == "." and i + 1 < len(tokens) and tokens[i + 1].type == "ident":
            classes.append(tokens[i + 1].value)
            i += 1
        elif t.type == "[] block":
            attrs.append(_parse_attr(t.content))
        elif t.type == "literal" and t.value == ":":
            nxt = tokens[i + 1] if i + 1 < len(tokens) else None
            if nxt is None or nxt.type != "ident" or nxt.lower_value not in ("first-child", "last-child"):
                raise _Unsupported
            pseudos.append(nxt.lower_value)
            i += 1
        elif t.type == "literal" and t.value == "|":
            raise _Unsupported  # namespace prefixes
        else:
            break
        i += 1
    if i == start:
        raise _Unsupported
    return Compound(tag, tuple(ids), tuple(classes), tuple(attrs), tuple(pseudos)), i


def _parse_attr(content: list) -> tuple[str, str, str]:
    toks = [t for t in content if t.type != "whitespace"]
    if not toks or toks[0].type != "ident":
        raise _Unsupported
    name = toks[0].value
    if len(toks) == 1:
        return (name, "", "")
    op = "".join(t.value for t in toks[1:-1] if t.type == "literal")
    if op not in _ATTR_OPS or toks[-1].type not in ("ident", "string"):
        raise _Unsupported
    return (name, op, toks[-1].value)


def _parse_selector(tokens: list) -> Selector:
    toks = list(tokens)
    while toks and toks[0].type == "whitespace":
        toks.pop(0)
    while toks and toks[-1].type == "whitespace":
        toks.pop()
    compounds: list[Compound] = []
    combinators: list[str] = []
    i = 0
    while True:
        comp, i = _parse_compound(toks, i)
        compounds.append(comp)
        if i >= len(toks):
            break
        comb = " "
        while i < len(toks) and toks[i].type == "whitespace":
            i += 1
        if i < len(toks) and toks[i].type == "literal" and toks[i].value in _COMBINATORS:
            comb = toks[i].value
            i += 1
            while i < len(toks) and toks[i].type == "whitespace":
                i += 1
        if i >= len(toks):
            raise _Unsupported
        combinators.append(comb)
    return Selector(tuple(compounds), tuple(combinators))


def _split_commas(prelude: list) -> list[list]:
    groups: list[list] = [[]]
    for t in prelude:
        if t.type == "literal" and t.value == ",":
            groups.append([])
        else:
            groups[-1].append(t)
    return groups


@dataclass
class StyleSheet:
    """The rules of all ``<style>`` elements of a document, indexed for matching."""

    rules: list[Rule] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    _by_id: dict[str, list[int]] = field(default_factory=lambda: defaultdict(list))
    _by_class: dict[str, list[int]] = field(default_factory=lambda: defaultdict(list))
    _by_tag: dict[str, list[int]] = field(default_factory=lambda: defaultdict(list))
    _any: list[int] = field(default_factory=list)
    _work: int = 0
    _memo: dict[tuple[int, int, int], bool] = field(default_factory=dict)

    def add(self, text: str) -> None:
        """Add the rules of one style sheet (after those added before)."""
        nodes = tinycss2.parse_stylesheet(text, skip_comments=True, skip_whitespace=True)
        self._add_rules(nodes)

    def _add_rules(self, nodes: list) -> None:
        for node in nodes:
            if node.type == "qualified-rule":
                self._add_rule(node)
            elif node.type == "at-rule":
                self._at_rule(node)

    def _at_rule(self, node) -> None:
        kw = node.lower_at_keyword
        if kw == "media" and node.content is not None:
            media = tinycss2.serialize(node.prelude).strip().lower()
            if all(m.strip() in _MEDIA_OK or m.strip().startswith("screen") for m in media.split(",")):
                self._add_rules(
                    tinycss2.parse_rule_list(node.content, skip_comments=True, skip_whitespace=True)
                )
            return
        if kw == "import":
            self._note("ignored a CSS @import: external style sheets are not read")
        elif kw not in ("font-face", "namespace", "charset", "keyframes", "page"):
            self._note(f"ignored a CSS @{kw} rule")

    def _note(self, text: str) -> None:
        if text not in self.notes:
            self.notes.append(text)

    def _add_rule(self, node) -> None:
        decls = tuple(
            _declaration(n)
            for n in tinycss2.parse_blocks_contents(node.content, skip_comments=True, skip_whitespace=True)
            if n.type == "declaration"
        )
        if not decls:
            return
        for group in _split_commas(node.prelude):
            try:
                sel = _parse_selector(group)
            except _Unsupported:
                shown = tinycss2.serialize(group).strip()
                self._note(f"ignored the CSS selector {shown[:40]!r} (not supported)")
                continue
            idx = len(self.rules)
            self.rules.append(Rule(sel, sel.specificity, idx, decls))
            last = sel.compounds[-1]
            if last.ids:
                self._by_id[last.ids[0]].append(idx)
            elif last.classes:
                self._by_class[last.classes[0]].append(idx)
            elif last.tag is not None:
                self._by_tag[last.tag].append(idx)
            else:
                self._any.append(idx)

    def matching(self, el, tree) -> list[Rule]:
        """Return the rules matching element ``el`` of ``tree``, by ascending specificity and order."""
        if not self.rules:
            return []
        cand: set[int] = set(self._any)
        el_id = el.get("id")
        if el_id is not None:
            cand.update(self._by_id.get(el_id, ()))
        for c in (el.get("class") or "").split():
            cand.update(self._by_class.get(c, ()))
        cand.update(self._by_tag.get(tree.tag(el), ()))
        out = [
            self.rules[i]
            for i in cand
            if self._match(self.rules[i].selector, len(self.rules[i].selector.compounds) - 1, el, tree)
        ]
        out.sort(key=lambda r: (r.specificity, r.order))
        return out

    def _match(self, sel: Selector, i: int, el, tree) -> bool:
        self._work += 1
        if self._work > MAX_MATCH_WORK:
            raise LimitError(f"the CSS selectors need more than {MAX_MATCH_WORK:,} steps to match")
        if not _compound_matches(sel.compounds[i], el, tree):
            return False
        if i == 0:
            return True
        key = (id(sel), i, id(el))
        hit = self._memo.get(key)
        if hit is not None:
            return hit
        comb = sel.combinators[i - 1]
        result = False
        if comb == ">":
            p = tree.parent(el)
            result = p is not None and self._match(sel, i - 1, p, tree)
        elif comb == " ":
            p = tree.parent(el)
            while p is not None and not result:
                result = self._match(sel, i - 1, p, tree)
                p = tree.parent(p)
        elif comb == "+":
            s = tree.previous(el)
            result = s is not None and self._match(sel, i - 1, s, tree)
        else:  # "~"
            s = tree.previous(el)
            while s is not None and not result:
                result = self._match(sel, i - 1, s, tree)
                s = tree.previous(s)
        self._memo[key] = result
        return result


def _compound_matches(c: Compound, el, tree) -> bool:
    if c.tag is not None and tree.tag(el) != c.tag:
        return False
    if c.ids and any(el.get("id") != i for i in c.ids):
        return False
    if c.classes:
        have = (el.get("class") or "").split()
        if any(k not in have for k in c.classes):
            return False
    for name, op, value in c.attrs:
        v = el.get(name)
        if v is None or not _attr_ok(v, op, value):
            return False
    for p in c.pseudos:
        if p == "first-child" and tree.previous(el) is not None:
            return False
        if p == "last-child" and tree.following(el) is not None:
            return False
    return True


def _attr_ok(v: str, op: str, value: str) -> bool:
    if op == "":
        return True
    if op == "=":
        return v == value
    if op == "~=":
        return value in v.split()
    if op == "|=":
        return v == value or v.startswith(value + "-")
    if op == "^=":
        return bool(value) and v.startswith(value)
    if op == "$=":
        return bool(value) and v.endswith(value)
    return bool(value) and value in v  # "*="
