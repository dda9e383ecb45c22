"""``python -m tribodem``: the ``tribodem`` command, through the same entry as the installed
script (:func:`tribodem._entry.entry`: Ctrl-C handling, exit codes)."""

from tribodem._entry import entry

if __name__ == "__main__":
    entry()
