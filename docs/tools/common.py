"""Helpers the scripts of docs/tools share: reading perilin's particles.vtu and writing a report
file atomically. Standard library only (read_vtu imports numpy when called)."""
import os
import struct
import tempfile


def read_vtu(path):
    """The arrays of perilin's particles.vtu (raw appended, UInt64 headers) by name, as numpy arrays
    of shape (points, components)."""
    import numpy as np
    data = open(path, "rb").read()
    head, _, tail = data.partition(b"<AppendedData encoding=\"raw\">")
    start = tail.index(b"_") + 1
    arrays = {}
    for line in head.decode().splitlines():
        if "<DataArray" not in line:
            continue
        attr = dict(part.split("=", 1) for part in line.strip()[11:-2].split(" ") if "=" in part)
        attr = {k: v.strip('"') for k, v in attr.items()}
        off = start + int(attr["offset"])
        nbytes = struct.unpack("<Q", tail[off:off + 8])[0]
        dtype = {"Float64": "<f8", "Int32": "<i4", "Int64": "<i8", "UInt8": "u1"}[attr["type"]]
        a = np.frombuffer(tail[off + 8:off + 8 + nbytes], dtype=dtype)
        arrays[attr["Name"]] = a.reshape(-1, int(attr["NumberOfComponents"]))
    return arrays


def write_atomically(dest, text):
    """text to dest through a temporary file in the same directory, so that a reader never sees
    half a report and a failed run leaves the old one."""
    dest = os.path.abspath(dest)
    fd, part = tempfile.mkstemp(prefix="." + os.path.basename(dest) + ".", dir=os.path.dirname(dest))
    try:
        with os.fdopen(fd, "w") as f:
            f.write(text)
        os.chmod(part, 0o644)
        os.replace(part, dest)
    except BaseException:
        os.unlink(part)
        raise
