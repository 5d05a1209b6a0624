// Reads an MCAP file with Foxglove's own reader (@mcap/core) and checks it independently of adit's writer:
// the indexed reader (footer, summary, summary CRC, chunk indexes, message indexes, chunk CRCs) and the
// stream reader (every record from the start, chunk CRCs) must agree with each other and with the
// statistics; the data section CRC is recomputed; every message parses as JSON and validates against the
// JSON Schema Foxglove publishes for its schema name (@foxglove/schemas; adit.Status against the file's own).
// Prints a JSON summary on stdout; exits 1 with a message on any disagreement.
//   node read_mcap.js FILE.mcap [TOPIC=COUNT ...]   also: each TOPIC holds exactly COUNT messages
"use strict";
const fs = require("fs");
const { McapIndexedReader, McapStreamReader } = require("@mcap/core");
const { crc32 } = require("@foxglove/crc");
const foxgloveSchemas = require("@foxglove/schemas/jsonschema");
const fzstd = require("fzstd");
const Ajv = require("ajv");

function fail(message) {
  console.error("read_mcap: " + message);
  process.exit(1);
}

const decompressHandlers = {
  zstd: (buffer, size) => fzstd.decompress(buffer, new Uint8Array(Number(size))),
};

function validatorFor(ajv, schemaRecord) {
  const name = schemaRecord.name;
  if (name.startsWith("foxglove.")) {
    const official = foxgloveSchemas[name.slice("foxglove.".length)];
    if (!official) fail(`no published schema named ${name}`);
    return ajv.compile(official);
  }
  return ajv.compile(JSON.parse(new TextDecoder().decode(schemaRecord.data)));
}

async function main() {
  const path = process.argv[2];
  if (!path) fail("usage: node read_mcap.js FILE.mcap [TOPIC=COUNT ...]");
  const bytes = new Uint8Array(fs.readFileSync(path));
  const readable = {
    size: async () => BigInt(bytes.length),
    read: async (offset, length) => bytes.subarray(Number(offset), Number(offset + length)),
  };
  const reader = await McapIndexedReader.Initialize({ readable, decompressHandlers });
  if (reader.dataSectionCrc === undefined) fail("no data section CRC");
  const dataCrc = crc32(bytes.subarray(0, Number(reader.dataEndOffset)));
  if (dataCrc !== reader.dataSectionCrc) fail(`data section CRC ${dataCrc} != ${reader.dataSectionCrc}`);

  const ajv = new Ajv({ strict: false, allErrors: false });
  const validators = new Map();
  for (const [id, schema] of reader.schemasById) validators.set(id, validatorFor(ajv, schema));

  const topics = {};
  for (const channel of reader.channelsById.values()) {
    const schema = reader.schemasById.get(channel.schemaId);
    topics[channel.topic] = { schema: schema ? schema.name : "", schema_encoding: schema ? schema.encoding : "",
                              encoding: channel.messageEncoding, count: 0, last: null };
  }
  let lastLogTime = -1n;
  for await (const message of reader.readMessages({ validateCrcs: true })) {
    const channel = reader.channelsById.get(message.channelId);
    const entry = topics[channel.topic];
    if (message.logTime < lastLogTime) fail("messages out of log-time order");
    lastLogTime = message.logTime;
    let decoded;
    try {
      decoded = JSON.parse(new TextDecoder().decode(message.data));
    } catch (e) {
      fail(`${channel.topic}: message ${entry.count} is not JSON: ${e.message}`);
    }
    const validate = validators.get(channel.schemaId);
    if (validate && !validate(decoded))
      fail(`${channel.topic}: message ${entry.count} does not match ${entry.schema}: ${ajv.errorsText(validate.errors)}`);
    entry.count += 1;
    entry.last = decoded;
  }

  // The stream reader, from the first byte: same messages per channel.
  const stream = new McapStreamReader({ decompressHandlers, validateCrcs: true });
  stream.append(bytes);
  const streamed = {};
  let record;
  let sawFooter = false;
  while ((record = stream.nextRecord())) {
    if (record.type === "Message") streamed[record.channelId] = (streamed[record.channelId] || 0) + 1;
    if (record.type === "Footer") sawFooter = true;
  }
  if (!sawFooter || !stream.done()) fail("stream reader did not reach the footer");

  const stats = reader.statistics;
  if (!stats) fail("no statistics record");
  let total = 0;
  for (const [id, channel] of reader.channelsById) {
    const indexed = topics[channel.topic].count;
    const stated = Number(stats.channelMessageCounts.get(id) || 0n);
    if (indexed !== stated || (streamed[id] || 0) !== stated)
      fail(`${channel.topic}: indexed ${indexed}, streamed ${streamed[id] || 0}, statistics ${stated}`);
    total += indexed;
  }
  if (total !== Number(stats.messageCount)) fail(`messages: read ${total}, statistics ${stats.messageCount}`);

  const summary = { chunks: reader.chunkIndexes.length, messages: total, compression: [...new Set(reader.chunkIndexes.map((c) => c.compression))], topics: {} };
  for (const [topic, t] of Object.entries(topics)) {
    const out = { schema: t.schema, schema_encoding: t.schema_encoding, encoding: t.encoding, count: t.count };
    const last = t.last;
    if (last && last.point_stride) out.last_points = Buffer.from(last.data, "base64").length / last.point_stride;
    if (last && last.poses) {
      out.last_poses = last.poses.length;
      const p = last.poses[last.poses.length - 1];
      if (p) out.last_position = [p.position.x, p.position.y, p.position.z];
    }
    if (last && last.entities) out.last_lines = last.entities[0].lines[0].points.length / 2;
    summary.topics[topic] = out;
  }
  console.log(JSON.stringify(summary, null, 1));
  for (const expectation of process.argv.slice(3)) {
    const [topic, count] = expectation.split("=");
    const got = topics[topic] ? topics[topic].count : 0;
    if (got !== Number(count)) fail(`${topic}: ${got} messages, expected ${count}`);
  }
}

main().catch((e) => fail(e.stack || String(e)));
