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


def host_line(summary):
    """The machine and day of a bench, from a run's summary.json: speed
    figures belong to a host (the same commit took 1.43x longer per fluid step
    at 6k particles on one 2-core VM than on another, 11% less at 80k)."""
    import datetime
    return (f"Host: {summary.get('host', 'not recorded')}; "
            f"{datetime.date.today().isoformat()}.")
