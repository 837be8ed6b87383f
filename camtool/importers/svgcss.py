"""SVG style sheets applied as CSS does, before svgelements reads the document.

svgelements applies a ``<style>`` sheet in its own order: only to the elements after the
sheet, the ``#id`` rules before the ``.class`` rules whatever their specificity, an inline
style above every rule even ``!important`` ones, and only rules whose selector names one
element. Each of these would cut a shape a browser hides (``.off{display:none !important}``
over ``style="display:inline"``) or drop one it shows (``#b{display:inline}`` over
``.a{display:none}``). :func:`apply_style_sheets` computes the cascade itself and writes the
result into each element's ``style`` attribute; the sheets are then removed, so svgelements
reads inline styles only.

The cascade (CSS Cascading and Inheritance Level 4, section 6; Selectors Level 3, section 9
for specificity), for each property of an element, highest first: an inline ``!important``
declaration; a sheet's ``!important`` declaration; the inline style; a sheet's declaration;
the presentation attribute (left where it is: svgelements ranks it below the style). Among
sheet declarations the more specific selector wins, then the later one. Inheritance is
svgelements' (it passes a group's style down).

Selectors applied: compound selectors (``*``, a type, ``#id``, ``.class``, ``:root``, any
together: ``path.cut.outer``, ``rect#a``) joined by descendant (space) or child (``>``)
combinators. Custom properties (``--ink``) are then resolved where ``var()`` uses them
(:mod:`camtool.importers.svgvars`).
Others (attributes ``[x]``, pseudo-classes ``:first-child``, sibling combinators ``+``/``~``,
at-rules ``@media``) are not applied: :func:`apply_style_sheets` refuses such a rule if it
hides what it selects, and names the others in a warning (``@font-face`` excepted: a font
styles nothing).
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from collections import Counter
from collections.abc import Iterator
from dataclasses import dataclass

from camtool.model.errors import InputError

SVG_NS = "http://www.w3.org/2000/svg"


_LOCAL_NAMES: dict[object, str | None] = {}
""":func:`local_name` by tag, for the first :data:`_LOCAL_NAMES_KEPT` tags met (every pass
over a document asks it of every element)."""
_LOCAL_NAMES_KEPT = 1024


def local_name(element: ET.Element) -> str | None:
    """The tag without the SVG namespace; ``None`` for elements of other namespaces."""
    tag = element.tag
    try:
        return _LOCAL_NAMES[tag]
    except KeyError:
        pass
    name: str | None = tag
    if not isinstance(tag, str):
        name = None  # comments, processing instructions
    elif tag.startswith("{"):
        ns, _, local = tag[1:].partition("}")
        name = local if ns == SVG_NS else None
    if len(_LOCAL_NAMES) < _LOCAL_NAMES_KEPT:
        _LOCAL_NAMES[tag] = name
    return name


_CSS_COMMENT = re.compile(r"/\*.*?\*/", re.DOTALL)
_KEYWORDS = frozenset({"none", "hidden", "collapse", "visible", "inline", "block"})
"""Values read as keywords, any case (``NONE``); ``currentColor`` stays as svgelements knows it."""
_IMPORTANT = re.compile(r"\s*!\s*important\s*$", re.IGNORECASE)
_PRESENTATION = ("display", "visibility", "fill", "stroke")
_COMPOUND = re.compile(r"(\*|[A-Za-z_][\w-]*)?((?:[#.][\w-]+)*)(:root)?", re.IGNORECASE)
_COMBINATOR_OR_COMPOUND = re.compile(r"\s*(>)\s*|\s+|([^\s>]+)")
_HIDING = ("display:none", "visibility:hidden", "visibility:collapse")
_IMPORT = re.compile(r"@import\b[^;{]*", re.IGNORECASE)


def _css_rules(text: str) -> list[tuple[str, str]]:
    """``(selector list, declarations)`` of a style sheet; an at-rule's body as one text."""
    text = _CSS_COMMENT.sub("", text)
    rules: list[tuple[str, str]] = []
    at = 0
    while (opening := text.find("{", at)) >= 0:
        depth, end = 1, opening + 1
        while end < len(text) and depth:
            depth += {"{": 1, "}": -1}.get(text[end], 0)
            end += 1
        # a statement before it (@import url(a.css); @charset "x";) is no part of its selector
        prelude = text[at:opening].rsplit(";", 1)[-1]
        rules.append((prelude.strip(), text[opening + 1 : end - 1]))
        at = end
    return rules


def _declaration_list(text: str) -> list[tuple[str, str, bool]]:
    """``(property, value, important)`` of CSS declarations, in their order.

    Property names in lower case, keywords (:data:`_KEYWORDS`) too; comments and
    ``!important`` taken off. A piece without a colon belongs to the value before it (a
    ``data:`` URL's ``;``).
    """
    out: list[tuple[str, str, bool]] = []
    if "/*" in text:
        text = _CSS_COMMENT.sub("", text)
    for item in text.split(";"):
        key, colon, value = item.partition(":")
        if not colon:
            if out and item.strip():
                name, before, important = out[-1]
                out[-1] = (name, f"{before};{item.strip()}", important)
            continue
        important = _IMPORTANT.search(value) is not None
        value = _IMPORTANT.sub("", value).strip()
        keyword = value.lower()
        out.append((key.strip().lower(), keyword if keyword in _KEYWORDS else value, important))
    return out


def inline_style(element: ET.Element) -> dict[str, str]:
    """The declarations of ``element``'s ``style`` attribute, ``{property: value}``, as written."""
    pairs = (item.split(":", 1) for item in element.get("style", "").split(";") if ":" in item)
    return {k.strip(): v.strip() for k, v in pairs}


def style_text(declarations: dict[str, str]) -> str:
    """``{property: value}`` as the text of a ``style`` attribute (see :func:`inline_style`)."""
    return ";".join(f"{k}:{v}" for k, v in declarations.items())


def normalize_styles(root: ET.Element) -> None:
    """Every ``style`` attribute and presentation attribute as svgelements reads it.

    CSS property names and keywords are case-insensitive, white space around a value is
    not part of it, a comment is white space and ``!important`` only ranks a declaration;
    svgelements compares the text, so ``display:none !important``, ``DISPLAY: NONE``,
    ``display:none/* off */`` or ``display="none "`` would hide nothing and the element
    would be cut.
    """
    for element in root.iter():
        style = element.get("style")
        if style and ("!" in style or "/*" in style or style != style.lower()):
            element.set("style", style_text({k: v for k, v, _ in _declaration_list(style)}))
        for attr in _PRESENTATION:
            value = element.get(attr)
            if value is not None and value != (word := value.strip().lower()) and word in _KEYWORDS:
                element.set(attr, word)
        _css_wide_keywords(element)
        _contents(element)


_UNBOXED = frozenset({"g", "svg", "use"})
"""Elements whose ``display: contents`` shows their content as without them (Chromium)."""


def _contents(element: ET.Element) -> None:
    """``display: contents`` on another SVG element is ``none``, as Chromium computes it.

    CSS Display 3 §2.8 leaves SVG elements to SVG; Chromium unboxes ``<g>``, ``<svg>`` and
    ``<use>`` and hides the rest (a ``<path>``, ``<a>``, ``<switch>``). svgelements knows
    no ``contents`` and would draw them.
    """
    style = element.get("style")
    in_style = bool(style) and "contents" in str(style).lower()
    in_attribute = element.get("display", "").strip().lower() == "contents"
    if not (in_style or in_attribute) or local_name(element) in _UNBOXED:
        return
    if in_attribute:
        element.set("display", "none")
    declared = inline_style(element)
    if declared.get("display", "").strip().lower() == "contents":
        declared["display"] = "none"
        element.set("style", style_text(declared))


_INITIAL = {
    "fill": "black",
    "stroke": "none",
    "color": "black",
    "display": "inline",
    "visibility": "visible",
    "opacity": "1",
    "fill-opacity": "1",
    "stroke-opacity": "1",
    "fill-rule": "nonzero",
    "clip-rule": "nonzero",
    "clip-path": "none",
    "mask": "none",
    "filter": "none",
    "stroke-dasharray": "none",
    "stroke-width": "1",
    "marker": "none",
    "marker-start": "none",
    "marker-mid": "none",
    "marker-end": "none",
    "stop-color": "black",
    "stop-opacity": "1",
}
"""The presentation properties camtool reads, and their initial values (SVG 1.1 Appendix
N, property index): what :func:`_css_wide_keywords` writes for ``initial``."""
_FROM_PARENT = frozenset({"inherit", "unset", "revert", "revert-layer"})
"""CSS-wide keywords that, for the properties of :data:`_INITIAL`, give the parent's value
(an inherited property's) or, for the few that are not inherited, one the group already
shows (``display``, ``opacity``, ``clip-path``, ``mask``)."""


def _css_wide_keywords(element: ET.Element) -> None:
    """Resolve the CSS-wide keywords (``inherit``, ``unset``, ``initial``, ``revert``).

    svgelements reads a keyword as a value: ``stroke="inherit"`` as black, which would cut
    a shape under ``<g stroke="none">`` that a viewer does not show, and leave one under a
    red group without a colour for a job to select. In a ``style`` (a style sheet's rules
    are there by now): ``inherit``, ``unset`` and ``revert`` remove the declaration, and
    the attribute it outranks, so the property comes from the parent (CSS Cascade 4
    §7.3); ``initial`` becomes the property's initial value (``stroke: initial`` is
    ``none``). As an attribute, ``inherit`` (SVG 1.1) and the keywords that are not valid
    there alike are removed.
    """
    style = element.get("style")
    if style and any(word in style.lower() for word in ("inherit", "unset", "initial", "revert")):
        declared = inline_style(element)
        changed = False
        for key, value in list(declared.items()):
            word = value.strip().lower()
            if key not in _INITIAL:
                continue
            if word in _FROM_PARENT:
                del declared[key]
                element.attrib.pop(key, None)
                changed = True
            elif word == "initial":
                declared[key] = _INITIAL[key]
                changed = True
        if changed:
            element.set("style", style_text(declared))
    for attr in _INITIAL.keys() & element.attrib.keys():
        if element.attrib[attr].strip().lower() in _FROM_PARENT | {"initial"}:
            del element.attrib[attr]


# ---------------------------------------------------------------------------- selectors


@dataclass(frozen=True)
class _Compound:
    """One compound selector: ``path.cut#a``; ``tag`` ``None`` for any (``*`` or none)."""

    tag: str | None
    ids: frozenset[str]
    classes: frozenset[str]
    root: bool = False  # :root, the document's root element

    def matches(self, element: ET.Element, classes: frozenset[str], is_root: bool) -> bool:
        if self.tag is not None and local_name(element) != self.tag:
            return False
        if self.root and not is_root:
            return False
        if self.ids and self.ids != {element.get("id")}:
            return False
        return self.classes <= classes


@dataclass(frozen=True)
class _Selector:
    """A selector read right to left, ``parts[0]`` its subject.

    ``child[i]``: whether ``parts[i + 1]`` must be the parent of ``parts[i]`` (``>``) or may
    be any ancestor (space).
    """

    parts: tuple[_Compound, ...]
    child: tuple[bool, ...]
    specificity: tuple[int, int, int]


def _compound(text: str) -> _Compound | None:
    match = _COMPOUND.fullmatch(text)
    if match is None or not text:
        return None
    names = re.findall(r"[#.][\w-]+", match.group(2))
    tag = match.group(1)
    return _Compound(
        None if tag in (None, "*") else tag,
        frozenset(n[1:] for n in names if n[0] == "#"),
        frozenset(n[1:] for n in names if n[0] == "."),
        match.group(3) is not None,
    )


def _selector(text: str) -> _Selector | None:
    """The selector ``text``, or ``None`` if it uses what :mod:`svgcss` does not apply."""
    parts: list[_Compound] = []
    child: list[bool] = []
    pending_child = False
    for match in _COMBINATOR_OR_COMPOUND.finditer(text.strip()):
        if match.group(1):
            if not parts or pending_child:
                return None
            pending_child = True
        elif match.group(2):
            compound = _compound(match.group(2))
            if compound is None:
                return None
            if parts:
                child.append(pending_child)
            parts.append(compound)
            pending_child = False
    if not parts or pending_child:
        return None
    ids = sum(len(p.ids) for p in parts)
    classes = sum(len(p.classes) + p.root for p in parts)
    tags = sum(p.tag is not None for p in parts)
    return _Selector(tuple(reversed(parts)), tuple(reversed(child)), (ids, classes, tags))


def _classes(element: ET.Element) -> frozenset[str]:
    return frozenset(element.get("class", "").split())


def _matches(
    selector: _Selector, element: ET.Element, parents: dict[ET.Element, ET.Element], at: int = 0
) -> bool:
    if not selector.parts[at].matches(element, _classes(element), element not in parents):
        return False
    if at + 1 == len(selector.parts):
        return True
    parent = parents.get(element)
    if selector.child[at]:
        return parent is not None and _matches(selector, parent, parents, at + 1)
    while parent is not None:
        if _matches(selector, parent, parents, at + 1):
            return True
        parent = parents.get(parent)
    return False


# ---------------------------------------------------------------------------- the cascade


@dataclass(frozen=True)
class _Rule:
    selector: _Selector
    order: int
    declarations: tuple[tuple[str, str, bool], ...]


def apply_style_sheets(
    root: ET.Element,
    parents: dict[ET.Element, ET.Element],
    name: str,
    unapplied: set[str],
) -> list[str]:
    """Apply every CSS ``<style>`` sheet to the elements' ``style`` attributes, then remove it.

    A sheet whose ``type`` is not ``text/css`` is removed unapplied.

    See the module docstring for the cascade and the selectors applied. A document without
    sheets is left as it is.

    Args:
        root: the ``<svg>`` element.
        parents: each element's parent (the removed sheets are taken out of it).
        name: the file, for messages.
        unapplied: the custom properties (``--ink``, in lower case) that a rule not
            applied declares are added to it (:func:`camtool.importers.svgvars.resolve_variables`
            refuses a value that needs one).

    Returns:
        A warning naming the rules not applied, if any (at-rules but ``@font-face``,
        pseudo-classes, attribute selectors, sibling combinators): what they style is read
        without them.

    Raises:
        InputError: a rule not applied would hide what it selects (``display:none``,
            ``visibility:hidden``, ``opacity:0``), so its elements would be cut; a rule
            of the user's actions (``:hover``) or of a pseudo-element excepted, which
            selects nothing in a still picture (:func:`_acted`).
    """
    sheets = list(root.iter(f"{{{SVG_NS}}}style" if root.tag.startswith("{") else "style"))
    if not sheets:
        return []
    rules: list[_Rule] = []
    ignored: list[str] = []
    for sheet in sheets:
        if sheet.get("type", "").strip().lower() not in ("", "text/css"):
            continue  # a sheet in another language: ignored (SVG 1.1 §6.16), as browsers do
        ignored += _IMPORT.findall(_CSS_COMMENT.sub("", sheet.text or ""))  # another file's sheet
        for selectors, body in _css_rules(sheet.text or ""):
            if selectors.startswith("@"):
                hiding = _media_hiding(selectors, body)
                if hiding is not None:
                    raise InputError(
                        f"{name}: the <style> rule '{selectors}' hides what it selects on a "
                        f"screen ({hiding}), but camtool does not apply rules inside "
                        f"{selectors.split()[0]}, so those elements would be cut; put {hiding} "
                        "on the elements themselves (a style attribute), or delete them"
                    )
                if not selectors.lower().startswith("@font-face"):  # a font styles nothing
                    ignored.append(selectors)
                    _custom_properties(body, unapplied, rules=True)
                continue
            declarations = tuple(_declaration_list(body))
            for text in (s.strip() for s in selectors.split(",")):
                selector = _selector(text)
                if selector is not None:
                    rules.append(_Rule(selector, len(rules), declarations))
                    continue
                hiding = next((f"{k}:{v}" for k, v, _ in declarations if _hides(k, v)), None)
                if hiding is not None and not _acted(text):
                    raise InputError(
                        f"{name}: the <style> rule '{text}' hides what it selects ({hiding}), "
                        "but camtool does not apply its selector (it applies types, .class, "
                        "#id, :root and their descendants), so those elements would be cut; put "
                        f"{hiding} on the elements themselves (a style attribute), or delete them"
                    )
                ignored.append(text)
                _custom_properties(body, unapplied)
    for sheet in sheets:
        parents[sheet].remove(sheet)
        del parents[sheet]
    if rules:
        _cascade(root, parents, rules)
    if not ignored:
        return []
    shown = ", ".join(f"'{s}'" for s in ignored[:3]) + (" ..." if len(ignored) > 3 else "")
    return [
        f"{name}: {len(ignored)} <style> rule(s) not applied ({shown}): camtool applies types, "
        ".class, #id, :root and their descendants; what they style is read without them"
    ]


def _custom_properties(body: str, into: set[str], *, rules: bool = False) -> None:
    """Add the custom properties ``body`` declares (a rule's; an at-rule's rules') to ``into``."""
    bodies = [inner for _, inner in _css_rules(body)] if rules else [body]
    into.update(k for text in bodies for k, _, _ in _declaration_list(text) if k.startswith("--"))


def labelled(root: ET.Element) -> Iterator[tuple[ET.Element, str, str]]:
    """``(element, kind, label)`` of each SVG element under ``root``, in document order.

    The label is how messages name it: ``rect#id``, else ``rect[n]``, the n-th of its kind.
    """
    seen: Counter[str] = Counter()
    for element in root.iter():
        kind = local_name(element)
        if kind is None:
            continue
        seen[kind] += 1
        ident = element.get("id")
        yield element, kind, f"{kind}#{ident}" if ident else f"{kind}[{seen[kind]}]"


def _media_hiding(at_rule: str, body: str) -> str | None:
    """The first hiding declaration of an at-rule's rules that a screen may apply, or ``None``.

    ``@media print`` (or ``speech``) applies to no screen and hides nothing there; any other
    media query (``screen``, ``all``, a width) may, as may ``@supports`` and ``@layer``.
    """
    words = at_rule.lower().split()
    if words[0].endswith("keyframes") or words[0] in ("@font-face", "@page", "@property"):
        return None  # an animation's frames (@-webkit-keyframes too), a font, a page box
    if words[0] == "@media" and all(_print_only(q) for q in " ".join(words[1:]).split(",")):
        return None
    for _, inner in _css_rules(body):
        for k, v, _ in _declaration_list(inner):
            if _hides(k, v):
                return f"{k}:{v}"
    return None


def _print_only(query: str) -> bool:
    """Whether the media query ``query`` (lower case) holds for print or speech alone."""
    words = query.split()
    if words[:1] == ["only"]:
        words = words[1:]
    return words[:1] in (["print"], ["speech"])


def _hides(prop: str, value: str) -> bool:
    """Whether the declaration hides what it styles (``display:none``, ``opacity:0``, ...)."""
    if prop == "opacity":
        text = value.strip()
        try:
            number = float(text[:-1] if text.endswith("%") else text)
        except ValueError:
            return False
        return number <= 0.0  # clamped to [0, 1]: at most 0 is 0
    return f"{prop}:{value}" in _HIDING


_ACTIONS = frozenset({"hover", "active", "focus", "focus-visible", "focus-within", "visited"})
"""Pseudo-classes of the user's actions (Selectors 4 §9): in a still picture they hold for
no element."""


def _acted(selector: str) -> bool:
    """Whether ``selector`` selects nothing in a still picture.

    It names a pseudo-class of the user's actions (``a:hover path``), outside a ``:not()``,
    or a pseudo-element (``::before``), which is no SVG shape. A structural pseudo-class
    (``:first-child``, ``:nth-child(2)``) selects in a still picture as anywhere.
    """
    if "::" in selector:
        return True
    if ":not(" in selector.lower():
        return False
    return any(name.lower() in _ACTIONS for name in re.findall(r":([A-Za-z-]+)", selector))


def _cascade(root: ET.Element, parents: dict[ET.Element, ET.Element], rules: list[_Rule]) -> None:
    """Write each element's cascaded style (sheet rules in ``rules``' order) into ``style``."""
    by_key: dict[str, list[_Rule]] = {}
    for rule in rules:  # indexed by what the subject names, so each element asks a few rules
        subject = rule.selector.parts[0]
        key = (
            f"#{min(subject.ids)}"
            if subject.ids
            else f".{min(subject.classes)}"
            if subject.classes
            else subject.tag or "*"
        )
        by_key.setdefault(key, []).append(rule)
    for element in root.iter():
        tag = local_name(element)
        if tag is None:
            continue
        keys = ["*", tag, *(f".{c}" for c in _classes(element))]
        if element.get("id"):
            keys.append(f"#{element.get('id')}")
        matched = [
            rule
            for key in keys
            for rule in by_key.get(key, ())
            if _matches(rule.selector, element, parents)
        ]
        if not matched:
            continue
        matched.sort(key=lambda r: (r.selector.specificity, r.order))
        normal: dict[str, str] = {}
        important: dict[str, str] = {}
        for rule in matched:
            for key, value, is_important in rule.declarations:
                (important if is_important else normal)[key] = value
        inline = _declaration_list(element.get("style", ""))
        normal.update((k, v) for k, v, i in inline if not i)
        normal.update(important)
        normal.update((k, v) for k, v, i in inline if i)
        element.set("style", style_text(normal))
