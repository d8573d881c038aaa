'use strict';
// Shared by serialize.js and check_stream.js: the messages sunvo sends, as node-mavlink
// classes, and the conversion between them and the JSON the C++ tests write.
// JSON conventions: uint64 as a decimal string, NaN as the string "NaN", field names as
// node-mavlink spells them (camelCase).
const { minimal, common } = require('node-mavlink');

const CLASSES = {
  0: minimal.Heartbeat,
  48: common.SetGpsGlobalOrigin,
  253: common.StatusText,
  331: common.Odometry,
};

function fromJsonNumber(v) {
  return v === 'NaN' ? NaN : v;
}

// A node-mavlink message object from {msgid, fields}.
function toMessage(entry) {
  const Clazz = CLASSES[entry.msgid];
  if (!Clazz) throw new Error(`unknown msgid ${entry.msgid}`);
  const msg = new Clazz();
  for (const [key, value] of Object.entries(entry.fields)) {
    if (!(key in msg)) throw new Error(`msgid ${entry.msgid}: no field ${key}`);
    if (key === 'timeUsec') msg[key] = BigInt(value);
    else if (Array.isArray(value)) msg[key] = value.map(fromJsonNumber);
    else msg[key] = fromJsonNumber(value);
  }
  return msg;
}

// Float fields travel as float32: compare against the expected value rounded to float32.
function sameValue(expected, actual) {
  if (typeof actual === 'bigint') return BigInt(expected) === actual;
  const e = fromJsonNumber(expected);
  if (Number.isNaN(e)) return Number.isNaN(actual);
  return Math.fround(e) === Math.fround(actual) && (Number.isInteger(e) ? e === actual : true);
}

// Differences between the expected JSON fields and a decoded message, as text lines.
function compareFields(expectedFields, decoded) {
  const errors = [];
  for (const [key, value] of Object.entries(expectedFields)) {
    const got = decoded[key];
    if (Array.isArray(value)) {
      if (!Array.isArray(got) || got.length !== value.length) {
        errors.push(`${key}: expected ${value.length} elements, got ${got}`);
        continue;
      }
      value.forEach((v, i) => {
        if (!sameValue(v, got[i])) errors.push(`${key}[${i}]: expected ${v}, got ${got[i]}`);
      });
    } else if (!sameValue(value, got)) {
      errors.push(`${key}: expected ${value}, got ${got}`);
    }
  }
  return errors;
}

module.exports = { CLASSES, toMessage, compareFields };
