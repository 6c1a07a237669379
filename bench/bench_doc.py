"""Writing a bench's markdown: the generated tables, then the hand-written
reading that follows them in the existing file, kept across reruns."""
import os


def write_keeping_notes(path, lines, marker):
    """Writes lines to path, followed by the old file's text from marker on
    (if the file and the marker exist)."""
    if os.path.exists(path):
        with open(path) as f:
            old = f.read()
        k = old.find(marker)
        if k >= 0:
            lines = lines + [old[k:].rstrip('\n'), '']
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    with open(path, 'w') as f:
        f.write('\n'.join(lines))
    return lines
