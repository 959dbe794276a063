"""Replaces the generated block of a doc page: the text between a begin and an end marker."""

import pathlib
import sys


def replace_block(path, begin, end, text):
    """Writes @p text between the markers @p begin and @p end of the file @p path (each kept on
    its own line); exits naming the file when a marker is missing."""
    doc = pathlib.Path(path)
    content = doc.read_text()
    if begin not in content or end not in content:
        sys.exit(f"{doc}: no markers {begin} ... {end}")
    head, rest = content.split(begin, 1)
    _, tail = rest.split(end, 1)
    doc.write_text(f"{head}{begin}\n{text}\n{end}{tail}")
