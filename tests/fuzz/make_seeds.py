#!/usr/bin/env python3
"""Writes the small seed corpora of tests/fuzz/corpus/ from the project's own files (launch files,
configuration, the KITTI mini set) and hand-built examples of each format. Run from the repository root;
node_messages and lidar_packets seeds are cut from logs/packets the tests produce (see README there)."""
import glob, os, struct

OUT = "tests/fuzz/corpus"

def put(harness, name, data):
    os.makedirs(f"{OUT}/{harness}", exist_ok=True)
    with open(f"{OUT}/{harness}/{name}", "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode())

def pcd_header(fields, sizes, types, n, data, counts=None):
    counts = counts or [1] * len(fields)
    return (f"# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS {' '.join(fields)}\n"
            f"SIZE {' '.join(map(str, sizes))}\nTYPE {' '.join(types)}\nCOUNT {' '.join(map(str, counts))}\n"
            f"WIDTH {n}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {n}\nDATA {data}\n").encode()

def lzf_literals(raw):
    out = bytearray()
    for i in range(0, len(raw), 32):
        chunk = raw[i:i + 32]
        out.append(len(chunk) - 1)
        out += chunk
    return bytes(out)

def pcd_seeds():
    pts = [(1.0 + i, 0.5 * i, -0.2 * i, 10.0 * i, i % 16, -0.1 + 0.01 * i) for i in range(8)]
    f, s, t = ["x", "y", "z", "intensity", "ring", "time"], [4, 4, 4, 4, 2, 4], ["F", "F", "F", "F", "U", "F"]
    ascii_body = "".join(f"{x} {y} {z} {i} {r} {tt}\n" for x, y, z, i, r, tt in pts)
    put("pcd", "ascii.pcd", pcd_header(f, s, t, len(pts), "ascii") + ascii_body.encode())
    put("pcd", "ascii_nan.pcd", pcd_header(f[:3], s[:3], t[:3], 2, "ascii") + b"nan nan nan\n1 2 3\n")
    binary = b"".join(struct.pack("<ffffHf", *p) for p in pts)
    put("pcd", "binary.pcd", pcd_header(f, s, t, len(pts), "binary") + binary)
    cols = b"".join(b"".join(struct.pack("<" + ("H" if k == 4 else "f"), p[k]) for p in pts) for k in range(6))
    comp = lzf_literals(cols)
    put("pcd", "compressed.pcd", pcd_header(f, s, t, len(pts), "binary_compressed") +
        struct.pack("<II", len(comp), len(cols)) + comp)
    # LZF back references: 8 zero points, the first literal, the rest copied.
    zeros = bytes(12 * 8)
    comp = bytes([0, 0]) + bytes([(7 << 5) | 0, len(zeros) - 1 - 2 - 7, 0])
    put("pcd", "compressed_backref.pcd", pcd_header(f[:3], s[:3], t[:3], 8, "binary_compressed") +
        struct.pack("<II", len(comp), len(zeros)) + comp)
    ouster = b"".join(struct.pack("<fffIB", 1.0, 2.0, 3.0, 1000 * i, i) for i in range(4))
    put("pcd", "ouster.pcd", pcd_header(["x", "y", "z", "t", "ring"], [4, 4, 4, 4, 1], ["F", "F", "F", "U", "U"], 4, "binary") + ouster)
    put("pcd", "counts.pcd", pcd_header(["x", "y", "z", "normal"], [8, 8, 8, 4], ["F", "F", "F", "F"], 1, "ascii", [1, 1, 1, 3])
        + b"1 2 3 0 0 1\n")

def kitti_seeds():
    seq = "../shared/data/kitti_mini/sequences/00"
    times = open(f"{seq}/times.txt").read().splitlines()[:3]
    text = ("\n".join(times) + "\n").encode()
    raw = open(f"{seq}/velodyne/000000.bin", "rb").read()
    for name, n in (("small", 64), ("rings", 400)):
        put("kitti", name, struct.pack("<H", len(text)) + text + raw[:16 * n])
    put("kitti", "one_time", struct.pack("<H", 5) + b"0.0\n\n" + raw[:160])

def lcmlog_seeds():
    def event(n, t, ch, data):
        return struct.pack(">IqqII", 0xEDA1DA01, n, t, len(ch), len(data)) + ch + data
    log = event(0, 1000, b"LIDAR_POINTS", bytes(40)) + event(1, 2000, b"IMU", bytes(range(30)))
    put("lcmlog", "two_events.lcmlog", log)
    put("lcmlog", "garbage_between.lcmlog", log[:50] + b"\x00" * 7 + log)
    put("lcmlog", "truncated.lcmlog", log[:-5])

def text_seeds():
    put("imu_text", "mixed.txt", "# bench\nt,gx,gy,gz,ax,ay,az,mx,my,mz\n10.000, 0.1, 0.2, 0.3, 0.0, 0.0, 9.81\n"
        "10.005 0.1 0.2 0.3 0.0 0.0 9.81 20 -5 40\n\n10.010,0.1,0.2,0.3,0.0,0.0\n10.015,0.1,abc,0.3,0.0,0.0,9.81\n"
        "1700000000123456789 0 0 0 0 0 9.8\n")
    for path in sorted(glob.glob("launch/config/*.yaml") + glob.glob("launch/sensors/*.yaml"))[:6]:
        put("config", os.path.basename(path), open(path, "rb").read())
    for path in sorted(glob.glob("launch/*.launch.yaml") + ["tests/integration/udp.launch.yaml"]):
        put("launch_file", os.path.basename(path), open(path, "rb").read())

def lidar_payload(rs16, k):
    """A VLP-16 (little-endian) or RS-16 (big-endian, 42-byte header) data packet, azimuth advancing with k."""
    order = ">" if rs16 else "<"
    body = b""
    for b in range(12):
        body += b"\xff\xee" + struct.pack(order + "H", (1000 + 40 * (12 * k + b)) % 36000)
        body += b"".join(struct.pack(order + "HB", 500 + 37 * i, i) for i in range(32))
    if rs16:
        head = bytes([0x55, 0xAA, 0x05, 0x0A, 0x5A, 0xA5, 0x50, 0xA0]) + bytes(12)
        head += bytes([24, 3, 15, 10, 20, 30]) + struct.pack(">HH", k, 0) + bytes(12)
        return head + body + b"\x00\xff" + bytes(4)
    return body + struct.pack("<I", 1000000 + 1327 * k) + b"\x37\x22"

def ipv4_udp(payload, port, ident, mtu=1500):
    udp = struct.pack(">HHHH", port, port, 8 + len(payload), 0) + payload
    step = (mtu - 20) // 8 * 8
    out = []
    for at in range(0, len(udp), step):
        chunk = udp[at:at + step]
        more = 0x2000 if at + step < len(udp) else 0
        out.append(struct.pack(">BBHHHBBH4s4s", 0x45, 0, 20 + len(chunk), ident, more | at // 8, 64, 17, 0,
                               bytes([192, 168, 1, 201]), bytes([192, 168, 1, 100])) + chunk)
    return out

def ws_frame(payload, opcode=1, fin=True, key=b"\x11\x22\x33\x44"):
    n = len(payload)
    head = bytes([(0x80 if fin else 0) | opcode])
    head += bytes([0x80 | n]) if n < 126 else bytes([0x80 | 126]) + struct.pack(">H", n)
    return head + key + bytes(b ^ key[i % 4] for i, b in enumerate(payload))

def web_seeds():
    get = "GET {} HTTP/1.1\r\nHost: robot:8080\r\nUser-Agent: test\r\n\r\n"
    put("web_server", "get_index", b"\x3f" + get.format("/").encode())
    put("web_server", "get_files", b"\x07" + (get.format("/app.js?v=2") + get.format("/../etc/passwd")).encode())
    upgrade = ("GET /ws HTTP/1.1\r\nHost: robot:8080\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
               "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n{}\r\n")
    frames = (ws_frame(b"save_map here") + ws_frame(b"frag", fin=False) + ws_frame(b"ment", opcode=0) +
              ws_frame(b"ping", opcode=9) + ws_frame(bytes(300), opcode=2) + ws_frame(b"", opcode=8))
    put("web_server", "websocket", b"\xff" + upgrade.format("").encode() + frames)
    put("web_server", "foxglove", b"\x02" + upgrade.format("Sec-WebSocket-Protocol: x, foxglove.websocket.v1\r\n").encode() +
        ws_frame(b'{"op":"subscribe","subscriptions":[{"id":1,"channelId":0},{"channelId":2, "id" : 7}]}') +
        ws_frame(b'{"op":"unsubscribe","subscriptionIds":[1, 7]}'))

def pcap_seeds():
    eth = lambda ip: bytes(6) + bytes([0x60, 0x76, 0x88, 0, 0, 2]) + b"\x08\x00" + ip
    # classic, microseconds, little-endian, Ethernet: three VLP-16 packets (model byte 0)
    f = struct.pack("<IHHiIII", 0xA1B2C3D4, 2, 4, 0, 0, 65535, 1)
    for k in range(3):
        frame = eth(ipv4_udp(lidar_payload(False, k), 2368, k)[0])
        f += struct.pack("<IIII", 1700000000, 1327 * k, len(frame), len(frame)) + frame
    put("pcap", "vlp16_classic_us.pcap", b"\x00" + f)
    # classic, nanoseconds, big-endian, raw IPv4: an RS-16 packet in 576-byte fragments, one out of order
    f = struct.pack(">IHHiIII", 0xA1B23C4D, 2, 4, 0, 0, 65535, 101)
    frags = ipv4_udp(lidar_payload(True, 0), 6699, 7, 576)
    frags[0], frags[1] = frags[1], frags[0]
    for i, ip in enumerate(frags):
        f += struct.pack(">IIII", 1700000000, 1000 * i, len(ip), len(ip)) + ip
    put("pcap", "rs16_fragments_ns_be.pcap", b"\x01" + f)
    # pcapng, big-endian: Linux cooked v2 interface in nanoseconds, an EPB and an SPB of RS-16 packets
    def block(t, body):
        body += bytes(-len(body) % 4)
        return struct.pack(">II", t, len(body) + 12) + body + struct.pack(">I", len(body) + 12)
    ng = block(0x0A0D0D0A, struct.pack(">IHHq", 0x1A2B3C4D, 1, 0, -1))
    ng += block(1, struct.pack(">HHI", 276, 0, 65535) + struct.pack(">HHB3x", 9, 1, 9) + bytes(4))
    sll2 = lambda ip: b"\x08\x00" + bytes(6) + b"\x00\x01\x00\x06" + bytes([0x60, 0x76, 0x88, 0, 0, 2, 0, 0]) + ip
    for k in range(2):
        frame = sll2(ipv4_udp(lidar_payload(True, k), 6699, k)[0])
        ng += block(6, struct.pack(">IIIII", 0, 395812, 1000 * k, len(frame), len(frame)) + frame)
    frame = sll2(ipv4_udp(lidar_payload(True, 2), 6699, 2)[0])
    ng += block(3, struct.pack(">I", len(frame)) + frame)
    put("pcap", "rs16_sll2_be.pcapng", b"\x01" + ng)

if __name__ == "__main__":
    pcd_seeds(); kitti_seeds(); lcmlog_seeds(); text_seeds(); pcap_seeds(); web_seeds()
