"""A small pure-Python LCM runtime: event-log reader/writer and UDP multicast pub/sub.

Debian 12 ships LCM's C, C++, Java and Lua bindings but no Python runtime (no python3-lcm),
so this module covers what sedbridge's Python users need, with the standard library only.
Its classes follow the names and calls of LCM's own Python module, so a script written
against it also runs with the real `lcm` where that is installed:

    try:
        import lcm
    except ImportError:
        import sedbridge_lcm as lcm

    for event in lcm.EventLog("out/replay/bridge.lcmlog"):      # event.channel, .data, .timestamp
        ...
    lc = lcm.LCM("udpm://239.255.76.67:7667?ttl=0")
    lc.subscribe("DISPLAY_COMMAND", lambda channel, data: ...)
    while True:
        lc.handle_timeout(100)

Plus `decode(data)`: the message of any sedbridge LCM type, found by its fingerprint
(needs the generated package `sedbridge`, build/lcmtypes/python).

Wire formats (LCM 1.x, big-endian):
  event log   per event: sync 0xEDA1DA01 (u32), event number (i64), timestamp [us] (i64),
              channel length (i32), data length (i32), channel bytes, data bytes
  UDP short   "LC02" magic (u32), sequence (u32), channel NUL-terminated, data
  UDP long    "LC03" magic (u32), sequence (u32), message size (u32), fragment offset (u32),
              fragment number (u16), fragment count (u16); fragment 0 starts with the
              NUL-terminated channel; offsets count data bytes only
"""

import collections
import os
import re
import select
import socket
import struct
import time

__all__ = ["Event", "EventLog", "LCM", "decode", "message_types", "parse_udpm_url"]

LOG_SYNC = 0xEDA1DA01
MAGIC_SHORT = 0x4C433032  # "LC02"
MAGIC_LONG = 0x4C433033   # "LC03"
_LOG_HEADER = struct.Struct(">IqqII")
_SHORT_HEADER = struct.Struct(">II")
_LONG_HEADER = struct.Struct(">IIIIHH")
# One datagram carries at most this much channel + data before LCM fragments (as lcm_udpm).
_SHORT_MAX = 1400
_FRAGMENT_MAX = 1400

Event = collections.namedtuple("Event", "eventnum timestamp channel data")


class EventLog(object):
    """An LCM event log (lcm-logger, `sedbridge replay`'s bridge.lcmlog).

    EventLog(path, "r") iterates Events; EventLog(path, "w") writes with write_event().
    Raises ValueError on a corrupt event (bad sync word or a truncated record).
    """

    def __init__(self, path, mode="r"):
        if mode not in ("r", "w"):
            raise ValueError("mode must be 'r' or 'w'")
        self.mode = mode
        self._f = open(path, "rb" if mode == "r" else "wb")
        self._next_eventnum = 0

    def close(self):
        self._f.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __iter__(self):
        while True:
            event = self.read_next_event()
            if event is None:
                return
            yield event

    def read_next_event(self):
        """The next Event, or None at the end of the log."""
        header = self._f.read(_LOG_HEADER.size)
        if not header:
            return None
        if len(header) < _LOG_HEADER.size:
            raise ValueError("truncated event header at byte %d" % (self._f.tell() - len(header)))
        sync, eventnum, timestamp, channel_len, data_len = _LOG_HEADER.unpack(header)
        if sync != LOG_SYNC:
            raise ValueError("not an LCM event log (sync word 0x%08x at byte %d)"
                             % (sync, self._f.tell() - _LOG_HEADER.size))
        channel = self._f.read(channel_len)
        data = self._f.read(data_len)
        if len(channel) < channel_len or len(data) < data_len:
            raise ValueError("truncated event %d" % eventnum)
        return Event(eventnum, timestamp, channel.decode("utf-8", "replace"), data)

    def write_event(self, timestamp, channel, data):
        """Appends one event; timestamp in microseconds."""
        channel_bytes = channel.encode("utf-8")
        self._f.write(_LOG_HEADER.pack(LOG_SYNC, self._next_eventnum, timestamp,
                                       len(channel_bytes), len(data)))
        self._f.write(channel_bytes)
        self._f.write(data)
        self._next_eventnum += 1


def parse_udpm_url(url):
    """(group, port, ttl) of 'udpm://GROUP:PORT?ttl=N'; LCM's defaults where parts are missing.

    An empty or None url reads $LCM_DEFAULT_URL, as LCM does.
    """
    if not url:
        url = os.environ.get("LCM_DEFAULT_URL", "") or "udpm://239.255.76.67:7667"
    m = re.match(r"^udpm://([0-9.]*)(?::(\d+))?(?:\?(.*))?$", url)
    if not m:
        raise ValueError("only udpm:// URLs are supported here, not %r" % url)
    group = m.group(1) or "239.255.76.67"
    port = int(m.group(2) or 7667)
    ttl = 0
    for option in (m.group(3) or "").split("&"):
        if option.startswith("ttl="):
            ttl = int(option[4:])
        elif option and not option.startswith(("recv_buf_size=", "transmit_only=")):
            raise ValueError("unknown udpm option %r in %r" % (option, url))
    return group, port, ttl


class _Subscription(object):
    def __init__(self, pattern, handler):
        self.pattern = pattern
        # LCM channel patterns are regular expressions matched against the whole name.
        self._regex = re.compile("^(?:%s)$" % pattern)
        self.handler = handler

    def matches(self, channel):
        return self._regex.match(channel) is not None


class LCM(object):
    """UDP multicast LCM (udpm:// only): publish(), subscribe(), handle(), handle_timeout().

    Handlers are called as handler(channel, data) like LCM's Python binding. Fragmented
    messages (larger than one datagram) are reassembled; a message whose fragments do not
    all arrive is dropped and counted in `incomplete`.
    """

    def __init__(self, url=None):
        self.group, self.port, self.ttl = parse_udpm_url(url)
        self._subs = []
        self._sequence = 0
        self._partial = {}  # (sender, sequence) -> [channel, size, bytearray, fragments left]
        self.incomplete = 0
        self._recv = None
        self._send = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
        self._send.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, self.ttl)
        self._send.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_LOOP, 1)

    def _open_receiver(self):
        s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
        s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        if hasattr(socket, "SO_REUSEPORT"):
            s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEPORT, 1)
        s.bind(("", self.port))
        mreq = struct.pack("4s4s", socket.inet_aton(self.group), socket.inet_aton("0.0.0.0"))
        s.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP, mreq)
        self._recv = s

    def close(self):
        self._send.close()
        if self._recv is not None:
            self._recv.close()

    def fileno(self):
        if self._recv is None:
            self._open_receiver()
        return self._recv.fileno()

    def subscribe(self, channel_pattern, handler):
        """handler(channel, data) for every message whose channel matches the regex."""
        if self._recv is None:
            self._open_receiver()
        sub = _Subscription(channel_pattern, handler)
        self._subs.append(sub)
        return sub

    def unsubscribe(self, subscription):
        self._subs.remove(subscription)

    def publish(self, channel, data):
        """Sends one message: one datagram, or fragments when it is large."""
        for packet in encode_packets(channel, bytes(data), self._sequence):
            self._send.sendto(packet, (self.group, self.port))
        self._sequence = (self._sequence + 1) & 0xFFFFFFFF

    def handle(self):
        """Blocks until one message was dispatched."""
        while not self.handle_timeout(1000):
            pass

    def handle_timeout(self, timeout_ms):
        """Waits up to timeout_ms for one complete message; True if one was dispatched."""
        deadline = time.monotonic() + timeout_ms / 1000.0
        fd = self.fileno()
        while True:
            left = deadline - time.monotonic()
            ready, _, _ = select.select([fd], [], [], max(0.0, left))
            if not ready:
                return False
            packet, sender = self._recv.recvfrom(65536)
            message = self.feed_packet(packet, sender)
            if message is not None:
                self._dispatch(*message)
                return True
            if left <= 0:
                return False

    def feed_packet(self, packet, sender=None):
        """(channel, data) when `packet` completes a message, else None. Bad packets are ignored."""
        if len(packet) < 4:
            return None
        (magic,) = struct.unpack_from(">I", packet)
        if magic == MAGIC_SHORT:
            return decode_short_packet(packet)
        if magic != MAGIC_LONG or len(packet) < _LONG_HEADER.size:
            return None
        _, sequence, size, offset, number, count = _LONG_HEADER.unpack_from(packet)
        body = packet[_LONG_HEADER.size:]
        key = (sender, sequence)
        if number == 0:
            nul = body.find(b"\0")
            if nul < 0:
                return None
            for stale in [k for k in self._partial if k[0] == sender and k != key]:
                del self._partial[stale]  # a newer message from this sender: drop the old one
                self.incomplete += 1
            self._partial[key] = [body[:nul].decode("utf-8", "replace"), size, bytearray(size), count]
            body = body[nul + 1:]
        entry = self._partial.get(key)
        if entry is None or offset + len(body) > entry[1]:
            return None
        entry[2][offset:offset + len(body)] = body
        entry[3] -= 1
        if entry[3] > 0:
            return None
        del self._partial[key]
        return entry[0], bytes(entry[2])

    def _dispatch(self, channel, data):
        for sub in list(self._subs):
            if sub.matches(channel):
                sub.handler(channel, data)


def decode_short_packet(packet):
    """(channel, data) of an "LC02" datagram, or None."""
    if len(packet) < _SHORT_HEADER.size:
        return None
    nul = packet.find(b"\0", _SHORT_HEADER.size)
    if nul < 0:
        return None
    return packet[_SHORT_HEADER.size:nul].decode("utf-8", "replace"), packet[nul + 1:]


def encode_packets(channel, data, sequence):
    """The datagrams LCM sends for one message (short, or fragments)."""
    channel_bytes = channel.encode("utf-8")
    if len(channel_bytes) + 1 + len(data) <= _SHORT_MAX:
        return [_SHORT_HEADER.pack(MAGIC_SHORT, sequence) + channel_bytes + b"\0" + data]
    first_room = _FRAGMENT_MAX - len(channel_bytes) - 1
    pieces = [data[:first_room]]
    pieces += [data[i:i + _FRAGMENT_MAX] for i in range(first_room, len(data), _FRAGMENT_MAX)]
    if len(pieces) > 0xFFFF:
        raise ValueError("message too large for LCM UDP (%d bytes)" % len(data))
    packets, offset = [], 0
    for number, piece in enumerate(pieces):
        header = _LONG_HEADER.pack(MAGIC_LONG, sequence, len(data), offset, number, len(pieces))
        packets.append(header + (channel_bytes + b"\0" if number == 0 else b"") + piece)
        offset += len(piece)
    return packets


_TYPES = None


def message_types():
    """{packed fingerprint: class} of the generated sedbridge LCM types."""
    global _TYPES
    if _TYPES is None:
        import sedbridge  # the lcm-gen --python package (build/lcmtypes/python)
        _TYPES = {}
        for name in dir(sedbridge):
            cls = getattr(sedbridge, name)
            if isinstance(cls, type) and hasattr(cls, "_get_packed_fingerprint"):
                _TYPES[cls._get_packed_fingerprint()] = cls
    return _TYPES


# Messages of a type's earlier version whose fields have since grown at the end: old
# fingerprint -> (type name, the bytes the new fields take when empty). lcmt_tactile_scan before
# num_shear, shear_x_kPa, shear_y_kPa decodes with num_shear 0 (as src/lcm/lcm_safe_decode.cpp).
_EARLIER_VERSIONS = {
    bytes.fromhex("3afe5a31ff1bfe44"): ("lcmt_tactile_scan", b"\0\0\0\0"),
}


def decode(data):
    """The decoded message of a sedbridge type; raises ValueError for an unknown type.

    A message of an earlier version of a type (see _EARLIER_VERSIONS) decodes as today's type,
    its newer fields empty."""
    earlier = _EARLIER_VERSIONS.get(bytes(data[:8]))
    if earlier is not None:
        import sedbridge
        cls = getattr(sedbridge, earlier[0])
        data = cls._get_packed_fingerprint() + bytes(data[8:]) + earlier[1]
    cls = message_types().get(bytes(data[:8]))
    if cls is None:
        raise ValueError("not a sedbridge LCM type (fingerprint %s)" % bytes(data[:8]).hex())
    return cls.decode(data)
