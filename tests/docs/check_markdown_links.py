#!/usr/bin/env python3
"""Checks the relative links of the repository's Markdown files.

Usage: check_markdown_links.py ROOT [--only DIR]

Every *.md file tracked by git under ROOT (or, without git, every *.md file under ROOT outside
build*/ and .git/) is read; with --only DIR, the *.md files under DIR instead, whether tracked or
not. Files under a path holding "broken_link_sample" are left out of the repository's scan: that
folder holds the broken links that show this checker fails.

Inline links and images, [text](target) and ![alt](target), outside fenced code blocks and inline
code spans, are resolved against their file's folder: the file or folder must exist, and an
anchor (file.md#anchor, or #anchor within the file) must be the slug of one of the target's
headings, by GitHub's rules (lower case; spaces to '-'; punctuation other than '-' and '_'
dropped; letters of any script kept; a repeated slug gets -1, -2, ...). Targets starting with
http:, https: or mailto: are not checked.

Prints each broken link as FILE:LINE: broken link TARGET (why) and exits 1 if there is any, else
prints "markdown links: N links in M files resolve" and exits 0.
"""
import os
import re
import subprocess
import sys
import unicodedata
import urllib.parse

SAMPLE = "broken_link_sample"
FENCE = re.compile(r"^ {0,3}(`{3,}|~{3,})")
LINK = re.compile(r"!?\[((?:[^\[\]]|\[[^\[\]]*\])*)\]\(\s*(<[^>]*>|[^)\s]+)(?:\s+(?:\"[^\"]*\"|'[^']*'))?\s*\)")
CODE_SPAN = re.compile(r"(`+)(.+?)\1")
HEADING = re.compile(r"^ {0,3}(#{1,6})\s+(.*?)\s*#*\s*$")
EXTERNAL = ("http:", "https:", "mailto:")


def markdown_files(root, only):
    """The .md files to check, as paths relative to root."""
    if only is not None:
        base = os.path.abspath(only)
        found = []
        for folder, dirs, files in os.walk(base):
            dirs.sort()
            for name in sorted(files):
                if name.endswith(".md"):
                    found.append(os.path.relpath(os.path.join(folder, name), root))
        return found
    try:
        listed = subprocess.run(["git", "ls-files", "-z", "--", "*.md"], cwd=root,
                                capture_output=True, check=True).stdout.decode("utf-8")
        files = [f for f in listed.split("\0") if f]
    except (OSError, subprocess.CalledProcessError):
        files = []
        for folder, dirs, names in os.walk(root):
            rel = os.path.relpath(folder, root)
            dirs[:] = sorted(d for d in dirs
                             if not (rel == "." and (d.startswith("build") or d == ".git")))
            for name in sorted(names):
                if name.endswith(".md"):
                    files.append(os.path.normpath(os.path.join(rel, name)))
    return [f for f in files if SAMPLE not in f.split("/") and SAMPLE not in f]


def prose_lines(text):
    """(line number, line) of the text outside fenced code blocks, inline code spans blanked."""
    fence = None
    for number, line in enumerate(text.split("\n"), start=1):
        opened = FENCE.match(line)
        if fence is None:
            if opened:
                fence = opened.group(1)
                continue
            yield number, CODE_SPAN.sub(lambda m: " " * len(m.group(0)), line)
        elif opened and opened.group(1)[0] == fence[0] and len(opened.group(1)) >= len(fence) \
                and line.strip() == opened.group(1):
            fence = None


def slug(heading):
    """GitHub's anchor for a heading's text."""
    text = re.sub(r"!?\[([^\]]*)\]\([^)]*\)", r"\1", heading)  # a link's text only
    text = re.sub(r"<[^>]+>", "", text)                        # inline HTML tags
    text = text.lower()
    kept = []
    for c in text:
        category = unicodedata.category(c)
        if c in "-_ " or category[0] in "LMN" or category == "Pc":
            kept.append(c)
    return "".join(kept).replace(" ", "-")


def anchors(path, cache):
    """The slugs of a Markdown file's headings (outside code blocks)."""
    if path not in cache:
        with open(path, encoding="utf-8") as f:
            text = f.read()
        seen = {}
        found = set()
        fence = None
        for line in text.split("\n"):
            opened = FENCE.match(line)
            if fence is None and opened:
                fence = opened.group(1)
                continue
            if fence is not None:
                if opened and line.strip() == opened.group(1) and opened.group(1)[0] == fence[0]:
                    fence = None
                continue
            m = HEADING.match(line)
            if not m:
                continue
            base = slug(m.group(2))
            n = seen.get(base, 0)
            seen[base] = n + 1
            found.add(base if n == 0 else f"{base}-{n}")
        cache[path] = found
    return cache[path]


def check(root, files):
    broken = []
    links = 0
    cache = {}
    for rel in files:
        path = os.path.join(root, rel)
        with open(path, encoding="utf-8") as f:
            text = f.read()
        for number, line in prose_lines(text):
            for m in LINK.finditer(line):
                target = m.group(2)
                if target.startswith("<") and target.endswith(">"):
                    target = target[1:-1]
                if target.lower().startswith(EXTERNAL):
                    continue
                links += 1
                where, _, anchor = target.partition("#")
                where = urllib.parse.unquote(where)
                anchor = urllib.parse.unquote(anchor)
                if where:
                    resolved = os.path.normpath(os.path.join(os.path.dirname(path), where))
                    if not os.path.exists(resolved):
                        broken.append(f"{rel}:{number}: broken link {target} (no such file or folder)")
                        continue
                else:
                    resolved = path
                if anchor:
                    if not resolved.endswith(".md") or os.path.isdir(resolved):
                        continue  # anchors into other kinds of file are not checked
                    if anchor not in anchors(resolved, cache):
                        name = os.path.relpath(resolved, root)
                        broken.append(f"{rel}:{number}: broken link {target} "
                                      f"(no heading of {name} has the anchor #{anchor})")
    return links, broken


def main(argv):
    args = argv[1:]
    only = None
    if "--only" in args:
        i = args.index("--only")
        if i + 1 >= len(args):
            print("check_markdown_links.py: --only needs a folder", file=sys.stderr)
            return 2
        only = args[i + 1]
        del args[i:i + 2]
    if len(args) != 1:
        print("usage: check_markdown_links.py ROOT [--only DIR]", file=sys.stderr)
        return 2
    root = os.path.abspath(args[0])
    files = markdown_files(root, only)
    links, broken = check(root, files)
    for line in broken:
        print(line)
    if broken:
        print(f"markdown links: {len(broken)} of {links} links in {len(files)} files are broken")
        return 1
    print(f"markdown links: {links} links in {len(files)} files resolve")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
