"""NatNet frame decoding: hand-built packets, every layout, truncated and garbage input."""

from __future__ import annotations

import random
import struct

import pytest

from ertools.live.natnet import (
    LAYOUTS,
    NAT_FRAMEOFDATA,
    FrameDecoder,
    FrameExtras,
    FrameOfData,
    NatNetVersion,
    RigidBody,
    UndecodablePacketError,
    decode_frame,
    detect_version,
    encode_frame,
)

pytestmark = pytest.mark.xdist_group("timing")


def hand_built_31() -> bytes:
    """A NatNet 3.1 frame written field by field from the SDK description (not the encoder).

    One marker set "ms" with one marker, no legacy markers, two rigid bodies (ID 3 tracked,
    ID 6 not), one skeleton with one bone, two labeled markers, no force plates, one device
    with one channel of two samples, then the suffix.
    """
    p = struct.pack("<i", 4711)  # frame number
    p += struct.pack("<i", 1) + b"ms\0" + struct.pack("<i", 1) + struct.pack("<3f", 1, 2, 3)
    p += struct.pack("<i", 0)  # legacy markers
    p += struct.pack("<i", 2)
    p += struct.pack("<i3f4ffh", 3, 0.5, -1.25, 0.25, 0.0, 0.0, 0.6, 0.8, 0.0005, 1)
    p += struct.pack("<i3f4ffh", 6, 9.0, 9.0, 9.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0)
    p += struct.pack("<i", 1) + struct.pack("<ii", 77, 1)
    p += struct.pack("<i3f4ffh", 78, 0, 0, 0, 0, 0, 0, 1, 0, 1)
    p += struct.pack("<i", 2) + struct.pack("<i3ffhf", 1, 0, 0, 0, 0.01, 0, 0) * 2
    p += struct.pack("<i", 0)  # force plates
    p += struct.pack("<i", 1) + struct.pack("<ii", 5, 1) + struct.pack("<i2f", 2, 0.1, 0.2)
    p += struct.pack("<iid", 11, 12, 123.25)
    p += struct.pack("<QQQ", 1000, 2000, 3000)
    p += struct.pack("<h", 0)
    return struct.pack("<hH", NAT_FRAMEOFDATA, len(p)) + p


def test_hand_built_31_packet_decodes_to_its_fields() -> None:
    frame = decode_frame(hand_built_31(), NatNetVersion(3, 1))
    assert frame.frame_number == 4711
    assert [b.body_id for b in frame.rigid_bodies] == [3, 6]  # the skeleton bone is not a body
    rb = frame.rigid_bodies[0]
    # 0.5, -1.25, 0.25, 0.6?, 0.8? travel as float32: compare to float32-rounded values.
    assert rb.position == (0.5, -1.25, 0.25)
    f32 = struct.unpack("<2f", struct.pack("<2f", 0.6, 0.8))
    assert rb.orientation_xyzw == (0.0, 0.0, f32[0], f32[1])
    assert rb.mean_error == pytest.approx(0.0005, rel=1e-6)  # float32 relative precision
    assert rb.tracking_valid and not frame.rigid_bodies[1].tracking_valid
    assert frame.timestamp_s == 123.25
    assert (frame.timecode, frame.timecode_sub) == (11, 12)
    assert (frame.stamp_camera_mid_exposure, frame.stamp_data_received, frame.stamp_transmit) == (
        1000,
        2000,
        3000,
    )
    # The same bytes are not a 4.0 frame (8 precision-timestamp bytes missing) nor 4.1.
    assert detect_version(hand_built_31())[0] == NatNetVersion(3, 1)


def _frame() -> FrameOfData:
    return FrameOfData(
        frame_number=42,
        rigid_bodies=(
            RigidBody(3, (1.5, -2.0, 0.25), (0.0, 0.0, 0.5, -0.5), 0.125, 1),
            RigidBody(5, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0), 0.0, 0),
        ),
        timestamp_s=12.5,
        timecode=1,
        timecode_sub=2,
        stamp_camera_mid_exposure=10,
        stamp_data_received=20,
        stamp_transmit=30,
        params=0,
    )


EXTRAS = FrameExtras(
    marker_sets=(("robot", ((1.0, 2.0, 3.0), (4.0, 5.0, 6.0))), ("all", ())),
    other_markers=((1.0, 1.0, 1.0),),
    skeletons=((1, (RigidBody(90, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)),)),),
    assets=((2, (RigidBody(91, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)),), 3),),
    labeled_markers=4,
    force_plates=((1, ((1.0, 2.0), (3.0,))),),
    devices=((7, ((0.5,),)),),
)


@pytest.mark.parametrize(
    "version",
    [
        NatNetVersion(3, 0),
        NatNetVersion(3, 1),
        NatNetVersion(4, 0),
        NatNetVersion(4, 1),
        NatNetVersion(4, 2),
    ],
)
@pytest.mark.parametrize("extras", [None, EXTRAS])
def test_round_trip_and_detection(version: NatNetVersion, extras: FrameExtras | None) -> None:
    frame = _frame()  # every value is exact in float32, so equality is exact
    packet = encode_frame(frame, version, extras)
    assert decode_frame(packet, version) == frame
    detected, again = detect_version(packet)
    # 3.0/3.1 share a layout, as do 4.1/4.2: detection names the representative.
    assert (detected.major, detected.has_byte_counts) == (version.major, version.has_byte_counts)
    assert again == frame


def test_layouts_differ_in_size() -> None:
    sizes = {str(v): len(encode_frame(_frame(), v)) for v in LAYOUTS}
    # 4.0 = 3.x + 8 bytes of precision timestamp; 4.1 adds a 4-byte byte count to each of the
    # 7 older sections plus the asset section (count and byte count: 8 bytes).
    assert sizes["4.0"] - sizes["3.1"] == 8
    assert sizes["4.1"] - sizes["4.0"] == 7 * 4 + 8


@pytest.mark.parametrize("version", LAYOUTS)
def test_every_truncation_is_undecodable(version: NatNetVersion) -> None:
    packet = encode_frame(_frame(), version, EXTRAS)
    for cut in range(len(packet)):
        with pytest.raises(UndecodablePacketError):
            decode_frame(packet[:cut], version)
        # A shortened payload with a header claiming the new size must fail too.
        body = packet[4:cut] if cut > 4 else b""
        with pytest.raises(UndecodablePacketError):
            decode_frame(struct.pack("<hH", NAT_FRAMEOFDATA, len(body)) + body, version)


@pytest.mark.slow
def test_garbage_never_raises_anything_else() -> None:
    rng = random.Random(7)
    good = encode_frame(_frame(), NatNetVersion(4, 1), EXTRAS)
    decoder = FrameDecoder()
    outcomes = {"decoded": 0, "undecodable": 0}
    for _ in range(3000):
        if rng.random() < 0.5:
            data = bytes(rng.randrange(256) for _ in range(rng.randrange(0, 120)))
        else:  # a frame with a few corrupted bytes
            data = bytearray(good)
            for _ in range(rng.randrange(1, 4)):
                data[rng.randrange(4, len(data))] = rng.randrange(256)
            data = bytes(data)
        try:
            decoder.decode(data)
            outcomes["decoded"] += 1  # a corrupted float still decodes: a valid layout
        except UndecodablePacketError:
            outcomes["undecodable"] += 1
        decoder.version = None  # keep detecting
    assert outcomes["decoded"] > 0 and outcomes["undecodable"] > 1000


def test_unsupported_versions_and_message_ids() -> None:
    packet = encode_frame(_frame(), NatNetVersion(3, 1))
    for version in (NatNetVersion(2, 9), NatNetVersion(5, 0)):
        with pytest.raises(UndecodablePacketError, match="not supported"):
            decode_frame(packet, version)
    other = struct.pack("<hH", 5, len(packet) - 4) + packet[4:]
    with pytest.raises(UndecodablePacketError, match="message ID 5"):
        decode_frame(other, NatNetVersion(3, 1))
    with pytest.raises(ValueError):
        NatNetVersion.parse("four")
    assert NatNetVersion.parse("4.1") == NatNetVersion(4, 1)


def test_decoder_keeps_the_detected_version() -> None:
    decoder = FrameDecoder()
    assert decoder.decode(encode_frame(_frame(), NatNetVersion(4, 1))).frame_number == 42
    assert decoder.version == NatNetVersion(4, 1)
    with pytest.raises(UndecodablePacketError):
        decoder.decode(encode_frame(_frame(), NatNetVersion(3, 1)))


def test_impossible_count_is_refused_before_looping() -> None:
    packet = bytearray(encode_frame(_frame(), NatNetVersion(3, 1)))
    # Marker-set count (first int after the frame number) set to 2**30.
    packet[8:12] = struct.pack("<i", 1 << 30)
    with pytest.raises(UndecodablePacketError, match="impossible marker set count"):
        decode_frame(bytes(packet), NatNetVersion(3, 1))
