// Connects to adit view --foxglove with Foxglove's own protocol client (@foxglove/ws-protocol over `ws`),
// subscribes to every channel advertised, and for SECONDS counts messages per topic, each parsed as JSON and
// validated against Foxglove's published JSON Schema of its schema name (adit.Status: the advertised schema).
// Prints {topic: {schema, count}} as JSON; exits 1 on an invalid message or a protocol error.
//   node foxglove_ws.js ws://HOST:PORT/ws SECONDS
"use strict";
const { FoxgloveClient } = require("@foxglove/ws-protocol");
const WebSocket = require("ws");
const foxgloveSchemas = require("@foxglove/schemas/jsonschema");
const Ajv = require("ajv");

const [url, seconds = "10"] = process.argv.slice(2);
const fail = (m) => { console.error("foxglove_ws: " + m); process.exit(1); };
const ajv = new Ajv({ strict: false });
const client = new FoxgloveClient({ ws: new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]) });
const channels = new Map(), bySubscription = new Map(), topics = {};
let serverName = null;
client.on("error", (e) => fail(String(e)));
client.on("serverInfo", (info) => { serverName = info.name; });
client.on("advertise", (list) => {
  for (const c of list) {
    if (c.encoding !== "json" || c.schemaEncoding !== "jsonschema") fail(`${c.topic}: encoding ${c.encoding}/${c.schemaEncoding}`);
    const official = c.schemaName.startsWith("foxglove.") ? foxgloveSchemas[c.schemaName.slice(9)] : JSON.parse(c.schema);
    if (!official) fail(`no published schema ${c.schemaName}`);
    channels.set(c.id, { ...c, validate: ajv.compile(official) });
    topics[c.topic] = { schema: c.schemaName, count: 0 };
    bySubscription.set(client.subscribe(c.id), c.id);
  }
});
client.on("message", ({ subscriptionId, data }) => {
  const c = channels.get(bySubscription.get(subscriptionId));
  if (!c) fail(`message for unknown subscription ${subscriptionId}`);
  let decoded;
  try { decoded = JSON.parse(new TextDecoder().decode(data)); } catch (e) { fail(`${c.topic}: not JSON`); }
  if (!c.validate(decoded)) fail(`${c.topic}: does not match ${c.schemaName}: ${ajv.errorsText(c.validate.errors)}`);
  topics[c.topic].count += 1;
});
setTimeout(() => {
  if (!serverName) fail("no serverInfo");
  console.log(JSON.stringify({ server: serverName, topics }));
  process.exit(0);
}, Number(seconds) * 1000);
