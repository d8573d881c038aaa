'use strict';
// node check_stream.js <expected.json> <fd> [timeout_ms]
// Reads a MAVLink byte stream from file descriptor <fd> (the master side of a pseudo-terminal),
// splits and CRC-checks it with node-mavlink, decodes each packet and compares it, in order,
// with the expected entries {msgid, seq, sysid, compid, fields}. Exit status: 0 when every
// expected message arrived with equal values and no CRC error or unknown packet was seen; 1 on
// the first mismatch, CRC error or unknown packet; 2 on timeout.
const fs = require('fs');
const {
  MavLinkPacketSplitter, MavLinkPacketParser, minimal, common,
} = require('node-mavlink');
const { compareFields } = require('./messages');

const expected = JSON.parse(fs.readFileSync(process.argv[2], 'utf8'));
const fd = Number(process.argv[3]);
const timeoutMs = Number(process.argv[4] || 30000);
const REGISTRY = { ...minimal.REGISTRY, ...common.REGISTRY };

let index = 0;
let crcErrors = 0;
function fail(code, text) {
  process.stderr.write(`check_stream: ${text}\n`);
  process.exit(code);
}

const splitter = new MavLinkPacketSplitter({}, {
  onCrcError: () => {
    crcErrors += 1;
    fail(1, `CRC error before message ${index}`);
  },
});
const input = fs.createReadStream(null, { fd, autoClose: false, highWaterMark: 4096 });
input.on('error', (err) => fail(1, `read error after ${index} messages: ${err.message}`));
input.pipe(splitter).pipe(new MavLinkPacketParser()).on('data', (packet) => {
  const want = expected[index];
  const h = packet.header;
  const where = `message ${index} (msgid ${h.msgid}, seq ${h.seq})`;
  if (!want) fail(1, `${where}: more messages than expected`);
  if (h.magic !== 0xFD) fail(1, `${where}: not a MAVLink v2 frame`);
  if (h.msgid !== want.msgid) fail(1, `${where}: expected msgid ${want.msgid}`);
  if (h.seq !== want.seq) fail(1, `${where}: expected seq ${want.seq}`);
  if (h.sysid !== want.sysid || h.compid !== want.compid) {
    fail(1, `${where}: expected sysid/compid ${want.sysid}/${want.compid}, got ${h.sysid}/${h.compid}`);
  }
  const clazz = REGISTRY[h.msgid];
  if (!clazz) fail(1, `${where}: unknown message id`);
  const errors = compareFields(want.fields, packet.protocol.data(packet.payload, clazz));
  if (errors.length > 0) fail(1, `${where}:\n  ${errors.join('\n  ')}`);
  index += 1;
  if (index === expected.length) {
    if (crcErrors > 0 || splitter.invalidPackages > 0 || splitter.unknownPackagesCount > 0) {
      fail(1, `invalid ${splitter.invalidPackages}, unknown ${splitter.unknownPackagesCount}`);
    }
    process.stdout.write(`check_stream: ${index} messages decoded, CRCs good, values equal\n`);
    process.exit(0);
  }
});
setTimeout(() => fail(2, `timeout after ${timeoutMs} ms: ${index} of ${expected.length} messages`),
  timeoutMs);
