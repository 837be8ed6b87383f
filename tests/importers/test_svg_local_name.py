"""``local_name``: an element's SVG tag without its namespace, whatever the passes asked before.

Every pass over an SVG document asks it of every element, so its answers are kept by tag
for the first tags met. The expected names come from the XML namespaces spec: a tag in the
SVG namespace is its local part, a tag in another namespace is no SVG element (``None``),
a tag in no namespace is itself (a file without ``xmlns``, as some clip-art is saved), and
a comment or processing instruction is no element.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

from camtool.importers import svgcss
from camtool.importers.svgcss import SVG_NS, local_name


def test_names_in_and_out_of_the_svg_namespace() -> None:
    assert local_name(ET.Element(f"{{{SVG_NS}}}path")) == "path"
    assert local_name(ET.Element("{http://www.inkscape.org/namespaces/inkscape}path")) is None
    assert local_name(ET.Element("rect")) == "rect"
    assert local_name(ET.Comment("a comment")) is None
    assert local_name(ET.ProcessingInstruction("xml-stylesheet", "href='a.css'")) is None


def test_more_tags_than_are_kept_get_the_same_answers() -> None:
    count = svgcss._LOCAL_NAMES_KEPT + 500
    foreign = [ET.Element(f"{{urn:other:{i}}}g") for i in range(count)]
    plain = [ET.Element(f"tag{i}") for i in range(count)]
    for _ in range(2):  # the second time, from what was kept where it was
        assert [local_name(e) for e in foreign] == [None] * count
        assert [local_name(e) for e in plain] == [f"tag{i}" for i in range(count)]
        assert local_name(ET.Element(f"{{{SVG_NS}}}circle")) == "circle"
    assert len(svgcss._LOCAL_NAMES) <= svgcss._LOCAL_NAMES_KEPT
