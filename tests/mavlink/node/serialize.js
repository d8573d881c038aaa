'use strict';
// node serialize.js <messages.json>
// Serialises each {msgid, seq, sysid, compid, fields} entry with node-mavlink's own MAVLink v2
// serializer and prints one frame per line as lowercase hex. The C++ encoder must match.
const fs = require('fs');
const { MavLinkProtocolV2 } = require('node-mavlink');
const { toMessage } = require('./messages');

const entries = JSON.parse(fs.readFileSync(process.argv[2], 'utf8'));
for (const entry of entries) {
  const protocol = new MavLinkProtocolV2(entry.sysid, entry.compid);
  process.stdout.write(protocol.serialize(toMessage(entry), entry.seq).toString('hex') + '\n');
}
