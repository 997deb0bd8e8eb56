// The live-view test's client: Foxglove's own WebSocket client (@foxglove/ws-protocol) and its ROS 2
// decoders (@foxglove/rosmsg, @foxglove/rosmsg2-serialization), as the Foxglove app uses them.
// Usage: node client.mjs ws://HOST:PORT SECONDS. Subscribes every advertised channel, decodes every
// message with the channel's own schema, and prints one JSON line: per topic the schema name and
// encodings, messages received, decoded, decode errors, and the fields of the last message.
import wsProtocol from "@foxglove/ws-protocol";
import rosmsg from "@foxglove/rosmsg";
import serialization from "@foxglove/rosmsg2-serialization";
import WebSocket from "ws";

const { FoxgloveClient } = wsProtocol;
const { parse } = rosmsg;
const { MessageReader } = serialization;

const [url, seconds] = [process.argv[2], Number(process.argv[3] ?? "10")];
// The Foxglove SDK's server speaks the ws-protocol under the subprotocol names foxglove.sdk.v1
// (its current name) and foxglove.websocket.v1 (this client's); offer both.
const client = new FoxgloveClient({ ws: new WebSocket(url, ["foxglove.sdk.v1", FoxgloveClient.SUPPORTED_SUBPROTOCOL]) });
const bySubscription = new Map();
const topics = {};
let server = null;

client.on("serverInfo", (info) => { server = { name: info.name, encodings: info.supportedEncodings ?? [] }; });
client.on("advertise", (channels) => {
  for (const ch of channels) {
    const t = (topics[ch.topic] = { schemaName: ch.schemaName, schemaEncoding: ch.schemaEncoding,
      encoding: ch.encoding, received: 0, decoded: 0, errors: 0, error: "", last: null });
    let reader = null;
    try {
      reader = new MessageReader(parse(ch.schema, { ros2: true }));
    } catch (e) {
      t.error = `schema: ${e}`;
    }
    bySubscription.set(client.subscribe(ch.id), { t, reader });
  }
});
client.on("message", ({ subscriptionId, data }) => {
  const s = bySubscription.get(subscriptionId);
  if (!s) return;
  s.t.received += 1;
  try {
    const msg = s.reader.readMessage(data);
    s.t.decoded += 1;
    s.t.last = Object.keys(msg);
  } catch (e) {
    s.t.errors += 1;
    s.t.error = String(e);
  }
});
client.on("error", (e) => { console.error(`client error: ${e}`); });
// The summary at the end: after SECONDS, or at once on SIGINT (the test's "the graph is done").
function finish() {
  console.log(JSON.stringify({ server, topics }, (_, v) => (typeof v === "bigint" ? Number(v) : v)));
  client.close();
  process.exit(0);
}
setTimeout(finish, seconds * 1000);
process.on("SIGINT", finish);
