"""Reading a MeshCat recording (its messages, animation tracks and camera) and a live server's frames."""

from __future__ import annotations

import os


def recorded(html: str) -> bytes:
    """The MeshCat commands a static HTML recording replays (its base64 data URLs, decoded)."""
    import base64
    import re

    return b"".join(base64.b64decode(b) for b in re.findall(r"base64,([A-Za-z0-9+/=]+)\"\)", html))


def messages(html: str) -> list[dict]:
    """The MeshCat messages a static HTML recording replays, decoded (MessagePack)."""
    import base64
    import re

    import msgpack

    found = re.findall(r"base64,([A-Za-z0-9+/=]+)\"\)", html)
    return [msgpack.unpackb(base64.b64decode(b), raw=False, strict_map_key=False) for b in found]


def animation_tracks(html: str) -> dict[str, dict[str, list[tuple[int, object]]]]:
    """The recording's animation: per scene-tree path, per track (``.position``, ``.visible``, ...),
    its (frame, value) keys."""
    (animation,) = [m for m in messages(html) if m["type"] == "set_animation"]
    return {
        a["path"]: {t["name"]: [(k["time"], k["value"]) for k in t["keys"]] for t in a["clip"]["tracks"]}
        for a in animation["animations"]
    }


def three_js(point) -> tuple[float, float, float]:
    """A world point (z up) in MeshCat's three.js frame (y up): (x, z, -y)."""
    x, y, z = (float(v) for v in point)
    return x, z, -y


def recorded_camera(commands: bytes) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """The camera's position and target (three.js frame) last set in a recording's ``commands``
    (MessagePack: a 3-array of float64 after the property's or the message's name)."""
    import struct

    def triple(marker: bytes) -> tuple[float, ...]:
        at = commands.rindex(marker) + len(marker)
        at = commands.index(b"value\x93", at) + len(b"value\x93")
        values = []
        for _ in range(3):
            assert commands[at] == 0xCB, commands[at : at + 9]  # float64
            values.append(struct.unpack(">d", commands[at + 1 : at + 9])[0])
            at += 9
        return tuple(values)

    return triple(b"/Cameras/default/rotated/<object>\xa8property\xa8position"), triple(b"set_target")


def _websocket_frames(url: str, *, seconds: float) -> bytes:
    """Every payload a WebSocket server at ``url`` (ws://host:port) sends in ``seconds`` (a minimal
    client: the upgrade handshake, then unmasked server frames read until the time is up)."""
    import base64
    import socket
    import time

    host, port = url.removeprefix("ws://").split(":")
    with socket.create_connection((host, int(port)), timeout=seconds) as sock:
        key = base64.b64encode(os.urandom(16)).decode()
        sock.sendall(
            (
                f"GET / HTTP/1.1\r\nHost: {host}:{port}\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
                f"Sec-WebSocket-Key: {key}\r\nSec-WebSocket-Version: 13\r\n\r\n"
            ).encode()
        )
        data, deadline = b"", time.monotonic() + seconds
        while time.monotonic() < deadline:
            sock.settimeout(max(deadline - time.monotonic(), 0.01))
            try:
                chunk = sock.recv(1 << 16)
            except TimeoutError:
                break
            if not chunk:
                break
            data += chunk
    header, _, frames = data.partition(b"\r\n\r\n")
    assert header.startswith(b"HTTP/1.1 101"), header[:100]
    payloads, i = b"", 0
    while i + 2 <= len(frames):
        length, i = frames[i + 1] & 0x7F, i + 2
        if length == 126:
            length, i = int.from_bytes(frames[i : i + 2], "big"), i + 2
        elif length == 127:
            length, i = int.from_bytes(frames[i : i + 8], "big"), i + 8
        payloads += frames[i : i + length]
        i += length
    return payloads
