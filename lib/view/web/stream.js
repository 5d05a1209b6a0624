// Decodes adit view's binary frames (lib/view/view_stream.hpp has the layout), little-endian.
export const FrameType = { Submap: 1, SubmapPose: 2, Sweep: 3, Trajectory: 4, Loops: 5, Robot: 6, Info: 7, Reset: 8 };
const kPointScale = 0.01;

function reader(buffer) {
  const view = new DataView(buffer);
  let pos = 0;
  return {
    u8() { const v = view.getUint8(pos); pos += 1; return v; },
    u32() { const v = view.getUint32(pos, true); pos += 4; return v; },
    i64() { const v = view.getBigInt64(pos, true); pos += 8; return Number(v); },
    f32() { const v = view.getFloat32(pos, true); pos += 4; return v; },
    f64() { const v = view.getFloat64(pos, true); pos += 8; return v; },
    pose() {
      const p = [this.f64(), this.f64(), this.f64()];
      const q = [this.f32(), this.f32(), this.f32(), this.f32()];  // x, y, z, w
      return { position: p, quaternion: q };
    },
    points(n) {  // n x (i16 x, y, z) -> Float32Array of metres
      const out = new Float32Array(3 * n);
      for (let i = 0; i < 3 * n; ++i) { out[i] = view.getInt16(pos, true) * kPointScale; pos += 2; }
      return out;
    },
    bytes(n) { const out = new Uint8Array(buffer, pos, n); pos += n; return out; },
    floats(n) {
      const out = new Float32Array(n);
      for (let i = 0; i < n; ++i) { out[i] = view.getFloat32(pos, true); pos += 4; }
      return out;
    },
    rest() { return new TextDecoder().decode(new Uint8Array(buffer, pos)); },
  };
}

export function decodeFrame(buffer) {
  const r = reader(buffer);
  const type = r.u8();
  switch (type) {
    case FrameType.Submap: {
      const id = r.u32(), version = r.u32(), pose = r.pose(), n = r.u32();
      return { type, id, version, pose, points: r.points(n) };
    }
    case FrameType.SubmapPose:
      return { type, id: r.u32(), version: r.u32(), pose: r.pose() };
    case FrameType.Sweep: {
      const utime = r.i64(), pose = r.pose(), n = r.u32();
      const points = r.points(n);
      return { type, utime, pose, points, intensity: r.bytes(n) };
    }
    case FrameType.Trajectory: {
      const kind = r.u8(), replace = r.u8() === 1, n = r.u32();
      return { type, kind, replace, positions: r.floats(3 * n) };
    }
    case FrameType.Loops: {
      const n = r.u32();
      return { type, segments: r.floats(6 * n) };
    }
    case FrameType.Robot:
      return { type, utime: r.i64(), pose: r.pose() };
    case FrameType.Info:
      return { type, info: JSON.parse(r.rest()) };
    case FrameType.Reset:
      return { type };
    default:
      return null;
  }
}
