#!/usr/bin/env python3
"""Checks every internal link of the generated API reference (the `docs` target runs it).

Usage: check_links.py HTML_DIR

Reads every .html file under HTML_DIR with the standard library's html.parser and checks each
href and src that does not name a scheme (http:, https:, mailto:, javascript:, data:): the file it
names must exist under HTML_DIR, and its #fragment, if any, must be an id or a name in that file.
Links that leave HTML_DIR (../) are broken too: the reference must stand alone. Prints each
broken link with the page that holds it and exits 1 if there is one; prints the counts otherwise.
"""
import html.parser
import os
import re
import sys
import urllib.parse

SCHEME = re.compile(r"^[a-zA-Z][a-zA-Z0-9+.-]*:")


class Page(html.parser.HTMLParser):
    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.anchors = set()
        self.links = []

    def handle_starttag(self, tag, attrs):
        for name, value in attrs:
            if value is None:
                continue
            if name in ("id", "name"):
                self.anchors.add(value)
            elif name in ("href", "src"):
                self.links.append((tag, value))


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: check_links.py HTML_DIR")
    root = os.path.realpath(sys.argv[1])
    pages = {}
    for d, _, files in os.walk(root):
        for f in files:
            if f.endswith(".html"):
                path = os.path.join(d, f)
                p = Page()
                with open(path, encoding="utf-8", errors="replace") as fh:
                    p.feed(fh.read())
                pages[path] = p
    if not pages:
        sys.exit("check_links: no .html file under %s" % root)
    broken, checked = [], 0
    for path, page in sorted(pages.items()):
        for tag, link in page.links:
            if SCHEME.match(link) or link == "":
                continue
            checked += 1
            target, _, fragment = link.partition("#")
            target = urllib.parse.unquote(target)
            fragment = urllib.parse.unquote(fragment)
            dest = os.path.realpath(os.path.join(os.path.dirname(path), target)) if target else path
            rel = os.path.relpath(path, root)
            if not (dest == root or dest.startswith(root + os.sep)):
                broken.append("%s: <%s> %s leaves the reference's directory" % (rel, tag, link))
            elif not os.path.isfile(dest):
                broken.append("%s: <%s> %s: no such file" % (rel, tag, link))
            elif fragment and dest.endswith(".html") and fragment not in pages[dest].anchors:
                broken.append("%s: <%s> %s: no anchor #%s in %s"
                              % (rel, tag, link, fragment, os.path.relpath(dest, root)))
    for b in broken:
        print("check_links: " + b)
    print("check_links: %d pages, %d internal links, %d broken" % (len(pages), checked, len(broken)))
    sys.exit(1 if broken else 0)


if __name__ == "__main__":
    main()
