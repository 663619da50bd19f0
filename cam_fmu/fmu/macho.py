"""A universal (fat) Mach-O file from thin ones: FMI 2.0's ``darwin64`` binary serves Intel and Apple-silicon Macs.

Build time only. What ``lipo -create`` does, written out because Debian has lipo only inside LLVM (160 MB):
a big-endian header (magic 0xcafebabe, the number of architectures), one 20-byte ``fat_arch`` entry per
architecture (cputype, cpusubtype, offset, size, log2 of the alignment) and the thin files, each at an
offset aligned to 2**14 bytes (arm64's page size, a multiple of x86_64's). The thin files are copied
unchanged, so each keeps its own (ad-hoc) code signature.
"""
from __future__ import annotations

import struct
from pathlib import Path
from typing import Sequence

FAT_MAGIC = 0xCAFEBABE
MH_MAGIC_64 = 0xFEEDFACF  # a thin 64-bit Mach-O, little-endian on both architectures
ALIGN = 14  # log2 of the slices' alignment: 16 KiB


class MachOError(ValueError):
    """A file that is not a thin 64-bit Mach-O, or two slices of one architecture."""


def merge(thin: Sequence[Path], dest: Path) -> Path:
    """Write the universal binary of the thin 64-bit Mach-O files ``thin`` (distinct architectures) to ``dest``."""
    slices = []
    for path in thin:
        data = Path(path).read_bytes()
        if len(data) < 32 or struct.unpack_from("<I", data)[0] != MH_MAGIC_64:
            raise MachOError(f"{path}: not a thin 64-bit Mach-O file")
        slices.append((*struct.unpack_from("<ii", data, 4), data))
    if len({s[0] for s in slices}) != len(slices):
        raise MachOError(f"two slices of one architecture in {[str(p) for p in thin]}")
    header = struct.pack(">II", FAT_MAGIC, len(slices))
    offset, entries, body = len(header) + 20 * len(slices), [], b""
    for cputype, cpusubtype, data in slices:
        start = -(-offset // (1 << ALIGN)) << ALIGN  # the next aligned offset
        body += b"\0" * (start - offset) + data
        entries.append(struct.pack(">iiIII", cputype, cpusubtype, start, len(data), ALIGN))
        offset = start + len(data)
    Path(dest).write_bytes(header + b"".join(entries) + body)
    return Path(dest)


__all__ = ["MachOError", "merge"]
