// Cross-check of Aerie's MAVLink codec against node-mavlink (an independent implementation).
//   node node_crosscheck.cjs check MODULES FRAMES.bin EXPECTED.jsonl KEYHEX
//     decodes Aerie's frames with node-mavlink: CRC and signatures must be accepted and every
//     field equal the value Aerie wrote (EXPECTED: one JSON object per frame).
//   node node_crosscheck.cjs write MODULES EXPECTED.jsonl OUT.bin KEYHEX
//     writes, with node-mavlink, one frame per line of EXPECTED (signed where it says so).
// Exit status 0 and a last line "OK <n> frames" when everything agrees; 1 with the reasons otherwise.
'use strict';
const fs = require('fs');
const path = require('path');

const [mode, modules, a, b, keyhex] = process.argv.slice(2);
const mavlink = require(path.join(modules, 'node_modules', 'node-mavlink'));
const REGISTRY = { ...mavlink.minimal.REGISTRY, ...mavlink.standard.REGISTRY, ...mavlink.common.REGISTRY };
const key = Buffer.from(keyhex, 'hex');
const errors = [];

function readExpected(file) {
  return fs.readFileSync(file, 'utf8').split('\n').filter((l) => l.trim()).map((l) => JSON.parse(l));
}

function elementType(type) {
  return type.replace('[]', '').replace('uint8_t_mavlink_version', 'uint8_t');
}

function sameScalar(type, got, want) {
  if (type === 'float') return got === Math.fround(want);
  if (type === 'uint64_t' || type === 'int64_t') return typeof got === 'bigint' && got.toString() === want;
  return got === want;
}

function sameValue(field, got, want) {
  const type = elementType(field.type);
  if (field.type.endsWith('[]')) {
    if (type === 'char') return got === want;
    if (!Array.isArray(got) || got.length !== want.length) return false;
    return want.every((w, i) => sameScalar(type, got[i], w));
  }
  return sameScalar(type, got, want);
}

function toNode(field, value) {
  const type = elementType(field.type);
  const one = (v) => (type === 'uint64_t' || type === 'int64_t' ? BigInt(v) : v);
  if (field.type.endsWith('[]') && type !== 'char') return value.map(one);
  return one(value);
}

function check() {
  const expected = readExpected(b);
  const splitter = new mavlink.MavLinkPacketSplitter();
  const parser = new mavlink.MavLinkPacketParser();
  const packets = [];
  splitter.pipe(parser);
  parser.on('data', (p) => packets.push(p));
  parser.on('end', () => {
    if (splitter.invalidPackages !== 0) errors.push(`node-mavlink refused ${splitter.invalidPackages} frames (bad CRC)`);
    if (splitter.unknownPackagesCount !== 0) errors.push(`node-mavlink did not know ${splitter.unknownPackagesCount} frames`);
    if (packets.length !== expected.length) errors.push(`node-mavlink decoded ${packets.length} frames, Aerie wrote ${expected.length}`);
    packets.forEach((p, i) => {
      const want = expected[i];
      if (!want) return;
      const where = `frame ${i} (${want.name}, ${want.signed ? 'signed' : 'unsigned'})`;
      const h = p.header;
      if (h.msgid !== want.msgid || h.sysid !== want.sysid || h.compid !== want.compid || h.seq !== want.seq)
        errors.push(`${where}: header ${h.msgid} ${h.sysid}/${h.compid} seq ${h.seq} differs`);
      if (want.signed) {
        if (!p.signature) errors.push(`${where}: node-mavlink sees no signature`);
        else {
          if (!p.signature.matches(key)) errors.push(`${where}: node-mavlink refuses the signature`);
          if (p.signature.linkId !== want.link) errors.push(`${where}: link id ${p.signature.linkId}`);
          if (String(p.signature.timestamp) !== want.timestamp) errors.push(`${where}: timestamp ${p.signature.timestamp}`);
        }
      } else if (p.signature) {
        errors.push(`${where}: node-mavlink sees a signature`);
      }
      const clazz = REGISTRY[h.msgid];
      if (!clazz) {
        errors.push(`${where}: no node-mavlink class`);
        return;
      }
      const data = p.protocol.data(p.payload, clazz);
      const seen = new Set();
      for (const field of clazz.FIELDS) {
        seen.add(field.source);
        if (!(field.source in want.fields)) {
          errors.push(`${where}: field ${field.source} missing in Aerie's message`);
          continue;
        }
        const got = data[field.name];
        if (!sameValue(field, got, want.fields[field.source]))
          errors.push(`${where}: ${field.source} = ${String(got)}, Aerie wrote ${JSON.stringify(want.fields[field.source])}`);
      }
      for (const name of Object.keys(want.fields))
        if (!seen.has(name)) errors.push(`${where}: Aerie's field ${name} is not in node-mavlink's ${clazz.MSG_NAME}`);
    });
    finish(packets.length);
  });
  splitter.end(fs.readFileSync(a));
}

function write() {
  const expected = readExpected(a);
  const out = [];
  for (const want of expected) {
    const clazz = REGISTRY[want.msgid];
    if (!clazz) {
      errors.push(`${want.name}: no node-mavlink class for id ${want.msgid}`);
      continue;
    }
    const msg = new clazz();
    for (const field of clazz.FIELDS) msg[field.name] = toNode(field, want.fields[field.source]);
    const flags = want.signed ? mavlink.MavLinkProtocolV2.IFLAG_SIGNED : 0;
    const protocol = new mavlink.MavLinkProtocolV2(want.sysid, want.compid, flags);
    let buffer = protocol.serialize(msg, want.seq);
    if (want.signed) {
      // sign() takes milliseconds since the Unix epoch and stores (ms - 2015-01-01) * 100.
      const ms = mavlink.MavLinkProtocolV2.SIGNATURE_START_TIME + Number(want.timestamp) / 100;
      buffer = protocol.sign(buffer, want.link, key, ms);
    }
    out.push(buffer);
  }
  fs.writeFileSync(b, Buffer.concat(out));
  finish(out.length);
}

function finish(n) {
  for (const e of errors) console.log(e);
  if (errors.length) {
    console.log(`FAILED ${errors.length} disagreements`);
    process.exit(1);
  }
  console.log(`OK ${n} frames`);
}

if (mode === 'check') check();
else if (mode === 'write') write();
else {
  console.log('usage: node_crosscheck.cjs check|write MODULES IN OUT KEYHEX');
  process.exit(2);
}
