"""CRC-32 (the zlib / ISO-HDLC polynomial MCAP chunks and sections use), as fast as installed.

zlib-ng's ``crc32`` (a dependency) folds with carry-less multiplication: about 20 GB/s against
4 GB/s for the system zlib that CPython links (1.2.13 here). Checking the CRC of every chunk a
pose read inflates cost 18 % of the read of an hour of zstd MCAP with zlib, 3 % with zlib-ng.
zlib stays the fallback where no zlib-ng wheel exists: same results, only slower.
"""

from __future__ import annotations

try:
    from zlib_ng.zlib_ng import crc32 as _crc32
except ImportError:  # pragma: no cover - platforms without a zlib-ng wheel
    from zlib import crc32 as _crc32


def crc32(data: bytes | bytearray | memoryview) -> int:
    """CRC-32 of ``data``."""
    return int(_crc32(data))
