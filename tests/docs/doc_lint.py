#!/usr/bin/python3
"""The documentation's pages are whole: each Markdown page of the repository
(README.md, docs/, proto/, bench/) has at most one title and has it first,
every relative link points at a file of the repository, and no bench's
progress lines ("hard_cases: NAME: exit 0 after 23 s") sit in a page.

Why: the pages are partly written by the bench scripts and partly by hand,
and a section regenerated with `--only` and pasted in carried the script's
title block and its progress lines into docs/hard_cases.md (forty-eighth
session: the page had its title three times and twelve log lines inside
section 4). Code blocks (fenced or indented) are not read: a '#' there is a
shell comment, a link there an example.

usage: doc_lint.py [FILE.md...]   (from the repository root; default: every page)
"""
import glob
import os
import re
import sys

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..'))
LINK = re.compile(r'\[[^\]]*\]\(([^)\s]+)\)')
# What bench/*.py print while they run (bench/hard_cases.py's coupler() and
# static_run(), main()'s last line): never a page's text.
PROGRESS = re.compile(r'^[a-z_]+: (\S+: (/|exit -?\d+ after \d+ s|failed: )|wrote \S+$)')


def pages():
    found = ['README.md']
    for pattern in ('docs/*.md', 'proto/*.md', 'bench/*.md'):
        found += sorted(glob.glob(pattern, root_dir=ROOT))
    return found


def prose(path):
    """(line number, line) of the page's text outside code blocks."""
    fence = None
    with open(path, encoding='utf-8') as f:
        for number, line in enumerate(f, 1):
            line = line.rstrip('\n')
            marker = re.match(r'^\s*(```+|~~~+)', line)
            if marker:
                if fence is None:
                    fence = marker.group(1)
                elif marker.group(1).startswith(fence):
                    fence = None
                continue
            if fence is not None or line.startswith('    ') or line.startswith('\t'):
                continue
            yield number, line


def check(page):
    path = os.path.join(ROOT, page)
    problems = []
    titles = []
    for number, line in prose(path):
        if line.startswith('# '):
            titles.append(number)
        if PROGRESS.match(line):
            problems.append(f'{page}:{number}: a bench\'s progress line in the page: {line[:80]}')
        for link in LINK.finditer(line):
            target = link.group(1)
            if re.match(r'^[a-zA-Z][a-zA-Z+.-]*:', target) or target.startswith('#'):
                continue  # a URL or an anchor in the page
            file = target.split('#')[0]
            if not os.path.exists(os.path.normpath(os.path.join(os.path.dirname(path), file))):
                problems.append(f'{page}:{number}: link to {target}: no such file')
    if len(titles) > 1:
        problems.append(f'{page}: {len(titles)} titles ("# " lines, at lines '
                        f'{", ".join(map(str, titles))}): a page has one, its first line')
    elif titles and titles[0] != 1:
        problems.append(f'{page}:{titles[0]}: the title is not the first line')
    return problems


def main(argv):
    chosen = argv[1:] or pages()
    problems = []
    for page in chosen:
        if not os.path.exists(os.path.join(ROOT, page)):
            problems.append(f'{page}: no such page')
            continue
        problems += check(page)
    for p in problems:
        print(p)
    print(f'doc_lint: {len(chosen)} pages, {len(problems)} problems')
    return 1 if problems else 0


if __name__ == '__main__':
    sys.exit(main(sys.argv))
