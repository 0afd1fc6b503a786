"""What any single input may cost: the readers' limits, in one place, each with its reason.

docs/io.md ("The budget of one input") states them for users. A limit refuses with one
:class:`~ertools.errors.BagError` line that names the file, the record or byte offset, and
the limit (:func:`over_budget`); damage (a chunk that inflates past the size it declares) is
refused as damage, never as a limit.
"""

from __future__ import annotations

MiB = 1 << 20
GiB = 1 << 30

# One chunk (ROS1 or MCAP), uncompressed, or a chunk's stored bytes: readers hold whole
# chunks. Recorders close a chunk at 768 KiB (rosbag) to a few MiB (MCAP writers); a chunk
# goes past that only by its one largest message: a 4000x4000 occupancy grid is 16 MB, an
# uncompressed 4K colour image 25 MB. 256 MiB is ten times the largest of those, and the
# few groups a read holds at once (docs/io.md) stay near a gigabyte at worst.
MAX_CHUNK_BYTES = 256 * MiB

# All the chunks of one file, uncompressed, may declare at most this many times the file's
# size (plus one chunk's budget): the work of decompressing a file is then bounded by its
# size. zstd inflates a block of zeros 32,000 times and bz2 a million times, so a small
# file could otherwise keep a reader busy for hours; real logs compress 2-10 times (sensor
# data), a map of one value a few hundred times. At the slowest codec measured (bz2,
# 170 MB/s) this is at most ~6 us of work per byte of input per read.
MAX_INFLATE_PER_BYTE = 1000

# A storage file of a rosbag2 bag compressed file by file is decompressed to a temporary
# copy: at most this much disk (an hour-long GT log is 160 MB; a full day of the 2015
# logging, cameras excluded, a few GB).
MAX_FILE_COPY_BYTES = 16 * GiB

# A ROS1 record header (the ``name=value`` fields before a record's data): the largest one a
# writer makes is a connection record's, a topic name long; data is counted apart.
MAX_RECORD_HEADER_BYTES = 1 * MiB

# A rosbag2 ``metadata.yaml`` is read whole and parsed: one with a thousand topics and
# files is well under 1 MB.
MAX_METADATA_BYTES = 16 * MiB

# Nesting of a rosbag2 ``metadata.yaml`` (its YAML nodes: the real layout nests five deep)
# and of the message types a stored definition declares (a field of a type that holds a
# field of a type...: the deepest standard message, nav_msgs/Odometry, nests four deep).
# Parsers and deserializers recurse once per level.
MAX_NESTING = 64


def allowance(file_size: int) -> int:
    """The uncompressed bytes all chunks of a file of ``file_size`` bytes may declare."""
    return MAX_INFLATE_PER_BYTE * file_size + MAX_CHUNK_BYTES


def over_budget(where: str, amount: str, limit: int | str, name: str) -> str:
    """The one line of a refusal: ``where`` costs ``amount``, over the ``limit`` (bytes, or
    said in words) of the constant ``name``."""
    said = size_text(limit) if isinstance(limit, int) else limit
    return f"{where}: {amount}, over the budget of {said} ({name}, docs/io.md)"


def size_text(n: int) -> str:
    if n >= GiB and n % (GiB // 4) == 0:
        return f"{n / GiB:g} GiB"
    if n >= MiB and n % (MiB // 4) == 0:
        return f"{n / MiB:g} MiB"
    return f"{n} bytes"
