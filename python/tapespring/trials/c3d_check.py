"""Structure of a C3D file checked in pure Python, before ezc3d reads it.

ezc3d trusts the sizes written in a C3D file: a few overwritten bytes in the
parameter section can make it read past its buffers (the process dies with a
segmentation fault) or loop for minutes, and a file cut inside the parameter
section does the same. `check_c3d` walks the header and every parameter record
with `struct`, bounds every size by the file, and raises a `TrialError` naming
the first inconsistency, so that ezc3d only sees files whose layout holds
together. It reads the header block and the parameter section only (a few kB).

Layout (C3D format specification, c3d.org, "The C3D File Format User Guide",
chapters 2-3), with the reading rules of ezc3d 1.5+ (``Header.cpp``,
``Parameters.cpp``, ``Parameter.cpp``), so that nothing ezc3d accepts is refused:

- Header (512 bytes; ezc3d skips leading zero bytes some Vicon files carry):
  byte 0 the parameter block number p (1-based, 512-byte blocks), byte 1 the
  check byte 0x50; 16-bit words 2-6: points, analog values per frame, first and
  last frame (1-based), interpolation gap; words 7-8 the scale factor (float,
  negative for float data); word 9 the data block; word 10 analog samples per
  frame; words 11-12 the frame rate.
- Parameter section at byte 512 (p - 1): a 4-byte head (first-record offset,
  0x50, number of blocks, processor type 84 Intel / 85 DEC / 86 MIPS, which
  fixes the byte order and float format of the whole file), then records.
  A record: name length n (int8, negative = locked, 0 ends the section), id
  (int8; < 0 group, > 0 parameter of group -id), the name, a 16-bit offset from
  the offset field to the next record (0 = last). A group then holds a
  description (length byte + text); a parameter holds its type (int8: -1 char,
  1 byte, 2 int16, 4 float), its number of dimensions (int8, 0 = scalar), the
  dimensions (uint8 each), |type| x prod(dims) data bytes and a description.
  ezc3d requires each record to end exactly where the previous offset points.
"""

from __future__ import annotations

import math
import struct
from dataclasses import dataclass, field
from pathlib import Path

from .common import check_regular_file
from .trial import TrialError

__all__ = ["C3DLayout", "check_c3d"]

_BLOCK = 512
_CHECK_BYTE = 0x50
_PROCESSORS = {84: "Intel", 85: "DEC", 86: "MIPS"}
_PARAM_TYPES = {-1: "char", 1: "byte", 2: "int16", 4: "float"}
# The specification allows at most 7 dimensions per parameter.
_MAX_DIMS = 7
# Scalar parameters whose value the checks below read (group, parameter).
_WANTED = {("POINT", "FRAMES"), ("POINT", "USED"), ("ANALOG", "USED")}
# Per-channel analog parameters that ezc3d reads for every channel without checking that they
# exist or are long enough (a missing one crashes it, ezc3d 1.7.2).
_ANALOG_PER_CHANNEL = ("SCALE", "OFFSET")


@dataclass(frozen=True)
class C3DLayout:
    """What `check_c3d` found in the header and the parameter section.

    Attributes
    ----------
    processor : {"Intel", "DEC", "MIPS"}
        Processor type (byte order and float format of the file).
    n_points : int
        3-D points per frame (header word 2).
    n_analog_values : int
        Analog values per marker frame (header word 3: channels x samples per frame).
    n_frames : int or None
        Frames declared by the header (or ``POINT:FRAMES`` beyond 65534 frames);
        None if the file does not say.
    frames_in_file : int or None
        Whole frames the data section of the file holds (None if ``n_frames`` is None).
    float_data : bool
        Data stored as 4-byte floats (negative scale factor), else 16-bit integers.
    groups : dict of str -> list of str
        Group name -> its parameter names, in file order.
    """

    processor: str
    n_points: int
    n_analog_values: int
    n_frames: int | None
    frames_in_file: int | None
    float_data: bool
    groups: dict[str, list[str]] = field(default_factory=dict)


class _Reader:
    """Bounds-checked reads from the bytes of a file; raises TrialError past ``limit``."""

    def __init__(self, data: bytes, path: Path, order: str, dec: bool) -> None:
        self.data, self.path, self.order, self.dec = data, path, order, dec

    def need(self, pos: int, size: int, limit: int, what: str) -> None:
        if pos < 0 or pos + size > limit:
            end = "end of the file" if limit >= len(self.data) else f"byte {limit}"
            raise TrialError(
                self.path,
                f"corrupt C3D file: {what} at byte {pos} runs past the {end} (truncated or "
                "overwritten parameter section)",
            )

    def int8(self, pos: int) -> int:
        return struct.unpack_from("b", self.data, pos)[0]

    def uint8(self, pos: int) -> int:
        return self.data[pos]

    def uint16(self, pos: int) -> int:
        return struct.unpack_from(self.order + "H", self.data, pos)[0]

    def int16(self, pos: int) -> int:
        return struct.unpack_from(self.order + "h", self.data, pos)[0]

    def float32(self, pos: int) -> float:
        raw = self.data[pos : pos + 4]
        if self.dec:
            # VAX F floats: swap the 16-bit halves, then the IEEE value is 4 times too large.
            return struct.unpack("<f", raw[2:4] + raw[0:2])[0] / 4.0
        return struct.unpack(self.order + "f", raw)[0]


def check_c3d(path: str | Path) -> C3DLayout:
    """Check the header and the parameter section of a C3D file.

    Parameters
    ----------
    path : str or Path
        The C3D file.

    Returns
    -------
    C3DLayout
        The sizes declared by the file.

    Raises
    ------
    FileNotFoundError
        If the file does not exist.
    IsADirectoryError
        If the path is a folder.
    TrialError
        If the path is not a regular file (a FIFO, a socket, a device), the file is
        not a C3D file, is truncated in its header or parameter
        section, or has a record whose sizes do not fit (the message gives the
        byte offset and the record).
    """
    path = Path(path)
    check_regular_file(path)
    size = path.stat().st_size
    with path.open("rb") as fh:
        head = fh.read(_BLOCK + 64)
        if not head:
            raise TrialError(path, "not a C3D file: the file is empty")
        zeros = len(head) - len(head.lstrip(b"\0"))
        if zeros == len(head):
            raise TrialError(path, "not a C3D file: it starts with zero bytes only")
        if zeros:
            fh.seek(zeros)
            head = fh.read(_BLOCK)
        if len(head) < 24:
            raise TrialError(path, f"not a C3D file: {size} bytes, shorter than a C3D header")
        if head[1] != _CHECK_BYTE:
            raise TrialError(
                path,
                f"not a C3D file: header check byte is 0x{head[1]:02x}, expected 0x50",
            )
        p = head[0]
        param_start = _BLOCK * (p - 1)
        fh.seek(param_start)
        # The parameter section is at most 255 blocks (its block count is one byte).
        section = fh.read(255 * _BLOCK)
    if len(section) < 4:
        raise TrialError(
            path,
            f"corrupt C3D header: the parameter section (block {p}, byte {param_start}) lies "
            f"beyond the end of the {size}-byte file (truncated?)",
        )
    processor = section[3]
    if processor not in _PROCESSORS:
        raise TrialError(
            path,
            f"corrupt C3D file: unknown processor type {processor} at byte {param_start + 3} "
            "(expected 84, 85 or 86; header or parameter block number overwritten?)",
        )
    order = ">" if processor == 86 else "<"
    hdr = _Reader(head, path, order, processor == 85)
    n_points, n_analog_values = hdr.uint16(2), hdr.uint16(4)
    first, last = hdr.uint16(6), hdr.uint16(8)
    scale, data_block = hdr.float32(12), hdr.uint16(16)
    if not math.isfinite(scale):
        raise TrialError(path, f"corrupt C3D header: scale factor {scale} is not finite")
    if data_block <= p:
        raise TrialError(
            path,
            f"corrupt C3D header: the data section starts at block {data_block}, not after "
            f"the parameter section (block {p})",
        )
    data_start = _BLOCK * (data_block - 1)
    groups, values, counts = _walk_parameters(
        section, path, order, processor == 85, param_start, data_start
    )

    # Frames: ezc3d reads 1-based first/last frames and takes a zero first frame as 0-based.
    n_frames: int | None = None
    if last != 0xFFFF:
        n_frames = last - first + 1 if first else last + 1
        if n_frames < 0:
            raise TrialError(
                path, f"corrupt C3D header: last frame {last} is before first frame {first}"
            )
    elif values.get(("POINT", "FRAMES")) is not None:
        n_frames = int(values[("POINT", "FRAMES")])
    used = values.get(("POINT", "USED"))
    if n_points and used != n_points:
        raise TrialError(
            path,
            f"corrupt C3D file: the header declares {n_points} points but POINT:USED is "
            f"{'missing' if used is None else used}",
        )
    per_frame = hdr.uint16(18)
    if n_analog_values:
        channels = n_analog_values // per_frame if per_frame else 0
        if per_frame == 0 or channels * per_frame != n_analog_values:
            raise TrialError(
                path,
                f"corrupt C3D header: {n_analog_values} analog values per frame is not a "
                f"multiple of {per_frame} analog samples per frame",
            )
        for name in ("USED", *_ANALOG_PER_CHANNEL):
            count = counts.get(("ANALOG", name))
            if count is None or count < (1 if name == "USED" else channels):
                have = "missing" if count is None else f"{count} values"
                raise TrialError(
                    path,
                    f"corrupt C3D parameter section: the file has {channels} analog channels "
                    f"but ANALOG:{name} is {have}",
                )
    float_data = scale < 0
    bytes_per_frame = (4 * n_points + n_analog_values) * (4 if float_data else 2)
    frames_in_file = None
    if n_frames is not None and bytes_per_frame > 0:
        frames_in_file = max(0, size - data_start) // bytes_per_frame
        if frames_in_file < n_frames:
            raise TrialError(
                path,
                f"truncated C3D data: the file holds {frames_in_file} of the {n_frames} "
                "frames its header declares",
            )
    return C3DLayout(
        processor=_PROCESSORS[processor],
        n_points=n_points,
        n_analog_values=n_analog_values,
        n_frames=n_frames,
        frames_in_file=frames_in_file,
        float_data=float_data,
        groups=groups,
    )


def _walk_parameters(
    section: bytes, path: Path, order: str, dec: bool, param_start: int, data_start: int
) -> tuple[dict[str, list[str]], dict[tuple[str, str], float], dict[tuple[str, str], int]]:
    """Walk the parameter records as ezc3d does; check every size against the section's end.

    Positions are relative to ``section`` (the bytes from ``param_start``); messages give
    absolute byte offsets in the file. Returns the group -> parameter names, the values of the
    scalar parameters in ``_WANTED`` and the number of values of every parameter.
    """
    # Records may not run into the data section, nor past the end of the file.
    limit = min(len(section), data_start - param_start)
    r = _Reader(section, path, order, dec)
    if section[0] != 1:
        # ezc3d starts at byte (first byte + 3) and requires it to be byte 4, right after the head.
        raise TrialError(
            path,
            f"corrupt C3D parameter section: its first byte (byte {param_start}) is "
            f"{section[0]}, expected 1",
        )
    pos = 4
    group_names: dict[int, str] = {}
    params: list[tuple[int, str, int, float | None, int]] = []
    expected = pos
    while True:
        if pos != expected:
            raise TrialError(
                path,
                f"corrupt C3D parameter section: a record ends at byte {param_start + pos} "
                f"but its offset points to byte {param_start + expected}",
            )
        r.need(pos, 1, limit, "parameter record")
        n_name = r.int8(pos)
        if n_name == 0:
            break
        r.need(pos, 2 + abs(n_name) + 2, limit, "parameter record")
        ident = r.int8(pos + 1)
        raw_name = section[pos + 2 : pos + 2 + abs(n_name)]
        if ident == 0 or not all(0x20 < c < 0x7F for c in raw_name):
            raise TrialError(
                path,
                f"corrupt C3D parameter section: record at byte {param_start + pos} has "
                f"group id {ident} and name {raw_name[:16]!r} (overwritten bytes?)",
            )
        name = raw_name.decode("ascii").upper()
        where = f"{'group' if ident < 0 else 'parameter'} {name} (byte {param_start + pos})"
        at = pos + 2 + abs(n_name)
        offset = r.uint16(at)
        after_offset = at + 2
        if ident < 0:
            r.need(after_offset, 1, limit, where)
            end = after_offset + 1 + r.uint8(after_offset)
            group_names[-ident] = name
        else:
            r.need(after_offset, 2, limit, where)
            kind = r.int8(after_offset)
            if kind not in _PARAM_TYPES:
                raise TrialError(
                    path,
                    f"corrupt C3D parameter section: {where} has data type {kind} "
                    "(expected -1, 1, 2 or 4)",
                )
            n_dims = r.int8(after_offset + 1)
            if not 0 <= n_dims <= _MAX_DIMS:
                raise TrialError(
                    path,
                    f"corrupt C3D parameter section: {where} has {n_dims} dimensions "
                    f"(expected 0 to {_MAX_DIMS})",
                )
            r.need(after_offset + 2, n_dims, limit, where)
            dims = list(section[after_offset + 2 : after_offset + 2 + n_dims])
            if n_dims == 0 and kind != -1:
                dims = [1]  # a scalar (ezc3d reads a char scalar as empty)
            data_at = after_offset + 2 + n_dims
            n_bytes = abs(kind) * math.prod(dims) if dims else 0
            r.need(data_at, n_bytes + 1, limit, where)
            value = None
            if dims == [1] and kind in (2, 4):
                value = r.int16(data_at) if kind == 2 else r.float32(data_at)
            # Number of values (of strings for char, whose first dimension is the length).
            count = math.prod(dims[1:] if kind == -1 else dims) if dims else 0
            params.append((ident, name, pos, value, count))
            desc_at = data_at + n_bytes
            end = desc_at + 1 + r.uint8(desc_at)
        r.need(pos, end - pos, limit, where)
        if offset == 0:
            break
        expected = at + offset
        pos = end
    groups: dict[str, list[str]] = {name: [] for name in group_names.values()}
    values: dict[tuple[str, str], float] = {}
    counts: dict[tuple[str, str], int] = {}
    for ident, name, pos, value, count in params:
        if ident not in group_names:
            raise TrialError(
                path,
                f"corrupt C3D parameter section: parameter {name} (byte {param_start + pos}) "
                f"belongs to group {ident}, which the file does not define",
            )
        group = group_names[ident]
        groups[group].append(name)
        counts[(group, name)] = count
        if (group, name) in _WANTED and value is not None:
            values[(group, name)] = value
    if "POINT" not in groups:
        raise TrialError(path, "corrupt C3D parameter section: no POINT group")
    return groups, values, counts
