"""CSS custom properties (``--ink: none``) resolved where ``var()`` uses them.

svgelements reads ``fill: var(--ink)`` as a colour it does not know and draws the shape; a
browser draws it as ``--ink`` says, ``none`` included. So, once the style sheets are in
the ``style`` attributes (:func:`camtool.importers.svgcss.apply_style_sheets`), every
``var()`` of a declaration is replaced by what it stands for, as CSS Custom Properties
Level 1 says: a custom property is inherited (section 2), ``var(--name, fallback)`` takes
the property's value, else the fallback (section 3); a declaration with a ``var()`` that has
neither, or a cycle, is invalid at computed-value time and acts as ``unset`` (section 3.1),
which :func:`camtool.importers.svgcss.normalize_styles` then resolves. Names are compared
in lower case, as the style sheets' declarations are written. A presentation attribute
(``stroke="var(--ink)"``) is resolved the same way, as Chromium does; one that is invalid
is removed (it ranks below every style declaration: the property is then inherited or
initial, as ``unset`` makes it).
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET

from camtool.importers.svgcss import inline_style, labelled, local_name, style_text
from camtool.importers.svgtree import href
from camtool.model.errors import InputError

DECIDING = frozenset(
    {
        "display",
        "visibility",
        "opacity",
        "fill",
        "stroke",
        "fill-opacity",
        "stroke-opacity",
        "stroke-width",
    }
)
"""Properties that decide whether a shape shows: a ``var()`` in one that needs a custom
property a rule camtool does not apply may set is refused."""
PRESENTATION = DECIDING | {
    "color",
    "fill-rule",
    "stroke-linecap",
    "stroke-linejoin",
    "stroke-dasharray",
    "stroke-dashoffset",
    "stroke-miterlimit",
}
"""Presentation attributes whose ``var()`` is resolved."""
MAX_DEPTH = 32
"""Nested substitutions followed (a custom property whose value uses another); deeper is
invalid, as a cycle is."""
MAX_LENGTH = 65_536
"""Characters a substituted value may have: a longer one is invalid (browsers cap it too:
values that double at each of 30 properties would be a gigabyte)."""


_USED = re.compile(r"var\(\s*(--[^\s,)]+)", re.IGNORECASE)
"""The custom property a ``var()`` names."""


class _Unapplied(Exception):
    """A ``var()`` needs a custom property that a rule not applied declares."""

    def __init__(self, name: str) -> None:
        super().__init__(name)
        self.name = name


def resolve_variables(root: ET.Element, name: str, unapplied: set[str]) -> None:
    """Replace each ``var()`` of the styles and presentation attributes under ``root``.

    Args:
        root: the ``<svg>`` element, its style sheets applied.
        name: the file, for messages.
        unapplied: custom properties (lower case) declared by style-sheet rules camtool
            does not apply (:func:`~camtool.importers.svgcss.apply_style_sheets`).

    Raises:
        InputError: a property of :data:`DECIDING` uses a ``var()`` that is not defined
            here and that such a rule may define; or an element a ``<use>`` places uses one
            that each clone would take from its own place (:class:`_Clones`). The message
            names the element and the property.
    """
    clones: _Clones | None = None
    stack: list[tuple[ET.Element, dict[str, str]]] = [(root, {})]
    while stack:
        element, inherited = stack.pop()
        style = element.get("style")
        scope = inherited
        if style and "--" in style:
            own = {k.lower(): v for k, v in inline_style(element).items() if k.startswith("--")}
            scope = {**inherited, **own} if own else inherited
        if style and "var(" in style.lower():
            declared = inline_style(element)
            for key, value in declared.items():
                if not key.startswith("--") and "var(" in value.lower():
                    clones = clones or _Clones(root)
                    clones.check(element, key, value, name)
                    got = _resolved(root, element, key, value, scope, unapplied, name)
                    declared[key] = "unset" if got is None else got
            element.set("style", style_text(declared))
        for key in sorted(PRESENTATION.intersection(element.keys())):
            value = element.get(key, "")
            if "var(" in value.lower():
                clones = clones or _Clones(root)
                clones.check(element, key, value, name)
                got = _resolved(root, element, key, value, scope, unapplied, name)
                if got is None:
                    del element.attrib[key]
                else:
                    element.set(key, got)
        stack.extend((child, scope) for child in reversed(element))


class _Clones:
    """What ``<use>`` elements place, where a ``var()`` is each clone's own.

    A clone inherits from its ``<use>``, not from where the element it copies stands (CSS
    Scoping 1 §3.3.1, SVG 2 §5.6.1), so a custom property the copied element does not set
    itself (on it or between it and the element the ``<use>`` names) may differ from clone
    to clone; camtool resolves each element once, where it stands.
    """

    def __init__(self, root: ET.Element) -> None:
        self.root = root
        ids = {e.get("id"): e for e in root.iter() if e.get("id")}
        self.parents = {child: parent for parent in root.iter() for child in parent}
        self.placed: dict[ET.Element, ET.Element] = {}  # element -> the one a <use> names
        for use in root.iter():
            ref = href(use) if local_name(use) == "use" else ""
            target = ids.get(ref[1:]) if ref.startswith("#") else None
            for element in target.iter() if target is not None else ():
                self.placed.setdefault(element, target)  # type: ignore[arg-type]
        self.declared = {
            k.lower() for e in root.iter() for k in inline_style(e) if k.startswith("--")
        }

    def check(self, element: ET.Element, key: str, value: str, name: str) -> None:
        """Refuse ``key: value`` of ``element`` where clones may read it otherwise.

        Raises:
            InputError: ``element`` is (in) what a ``<use>`` places, and a property ``value``
                uses is set somewhere in the document but not within what is placed.
        """
        top = self.placed.get(element)
        if top is None:
            return
        within: set[str] = set()
        node: ET.Element | None = element
        while node is not None:
            within |= {k.lower() for k in inline_style(node) if k.startswith("--")}
            node = None if node is top else self.parents.get(node)
        for used in (u.lower() for u in _USED.findall(value)):
            if used in self.declared and used not in within:
                raise InputError(
                    f"{name}: {_label(self.root, element)}: {key}: {value} is placed by a <use>, "
                    f"whose clones take {used} from where each <use> stands, which camtool "
                    f"does not follow; set {used} on the element itself, or write the value"
                )


def _label(root: ET.Element, element: ET.Element) -> str:
    """``element``'s name in messages (``path#a``, ``rect[2]``: :func:`labelled`'s)."""
    return next((t for e, _, t in labelled(root) if e is element), str(element.tag))


def _resolved(
    root: ET.Element,
    element: ET.Element,
    key: str,
    value: str,
    scope: dict[str, str],
    unapplied: set[str],
    name: str,
) -> str | None:
    """``value`` of ``element``'s ``key`` substituted (``None``: invalid).

    Raises:
        InputError: see :func:`resolve_variables`.
    """
    try:
        return _substituted(value, scope, unapplied, 0, {})
    except _Unapplied as exc:
        if key.lower() not in DECIDING:
            return None
        raise InputError(
            f"{name}: {_label(root, element)}: {key}: {value} uses {exc.name}, which a <style> "
            "rule camtool does not apply sets, so it cannot tell whether the element shows; "
            f"write the value itself, or set {exc.name} in a rule of a type, .class, #id or "
            ":root"
        ) from None


def _substituted(
    value: str,
    scope: dict[str, str],
    unapplied: set[str],
    depth: int,
    known: dict[str, str | None],
) -> str | None:
    """``value`` with each ``var()`` replaced; ``None``: invalid (see the module).

    ``known``: each custom property's substituted value once worked out (``None``: invalid,
    or being worked out: a cycle), so each is worked out once however often it is used.

    Raises:
        _Unapplied: a ``var()`` without a value here nor a fallback names a property a rule
            not applied declares.
    """
    if depth > MAX_DEPTH:
        return None
    out: list[str] = []
    at = length = 0
    lowered = value.lower()
    while (start := lowered.find("var(", at)) >= 0:
        end = _closing(value, start + 4)
        if end is None:
            return None  # an unclosed var(: not a value CSS reads
        out.append(value[at:start])
        length += start - at
        name, comma, fallback = _split_arguments(value[start + 4 : end])
        name = name.strip().lower()
        got = None
        if name in known:
            got = known[name]
        elif name in scope and scope[name].strip().lower() != "initial":
            known[name] = None  # a use of it while it is worked out is a cycle
            got = known[name] = _substituted(scope[name], scope, unapplied, depth + 1, known)
        if got is None and comma:
            got = _substituted(fallback, scope, unapplied, depth + 1, known)
        if got is None:
            if name in unapplied and name not in scope:
                raise _Unapplied(name)
            return None
        out.append(got.strip())
        length += len(out[-1])
        if length > MAX_LENGTH:
            return None
        at = end + 1
    out.append(value[at:])
    return "".join(out).strip()


def _closing(text: str, at: int) -> int | None:
    """The index of the ``)`` that closes the bracket opened just before ``at``."""
    depth = 1
    for i in range(at, len(text)):
        if text[i] == "(":
            depth += 1
        elif text[i] == ")":
            depth -= 1
            if depth == 0:
                return i
    return None


def _split_arguments(text: str) -> tuple[str, bool, str]:
    """``var()``'s arguments split at the first comma outside brackets: name, comma, fallback."""
    depth = 0
    for i, char in enumerate(text):
        if char == "(":
            depth += 1
        elif char == ")":
            depth -= 1
        elif char == "," and depth == 0:
            return text[:i], True, text[i + 1 :]
    return text, False, ""
