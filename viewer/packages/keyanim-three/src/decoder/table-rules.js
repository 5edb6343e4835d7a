// What each profile allows in the section table: rules 3.2.2 and 3.2.3 (archive) and 9.1.1
// (runtime). Each returns { entry(e), end() }, called per table entry (e: index, tag,
// compressed, ancillary, entry = the entry's file offset, where = its name for messages) and
// once after the last; they throw KanimError. `member`: the table of a bank's member, which
// holds no SKEL (spec 10.5.2: its skeleton is the bank's). `major`: the file's Major_Version
// (version 5 adds QUAT, between SKEL and CHAN in the archive profile; none in the runtime's).
import { fail } from './errors.js';

const ARCHIVE_CRITICAL = ['CLIP', 'SKEL', 'CHAN', 'KTIM', 'KVAL'];
const ARCHIVE_CRITICAL_5 = ['CLIP', 'SKEL', 'QUAT', 'CHAN', 'KTIM', 'KVAL'];
const RUNTIME_SECTIONS = ['CLIP', 'IMAG', 'SKEL'];
const withoutSkel = (tags) => tags.filter((t) => t !== 'SKEL');

function refuseMemberSkel(e) {
  if (e.tag === 'SKEL') fail('corrupt', 'section table', e.entry, `${e.where}: a bank's member holds no SKEL (its skeleton is the bank's)`);
}

// NOTE: at most once, ancillary (3.2.3; 9.1.2 keeps it in the runtime profile).
function checkNote(e, seen) {
  if (!e.ancillary) fail('corrupt', 'section table', e.entry + 4, `${e.where}: NOTE must be ancillary`);
  if (seen) fail('corrupt', 'section table', e.entry, `${e.where}: a second NOTE section`);
}

export function archiveRules(member = false, major = 3) {
  const all = major >= 5 ? ARCHIVE_CRITICAL_5 : ARCHIVE_CRITICAL;
  const CRITICAL = member ? withoutSkel(all) : all;
  let nextCritical = 0, notes = 0;
  return {
    entry(e) {
      if (member) refuseMemberSkel(e);
      const critical = CRITICAL.indexOf(e.tag);
      if (critical >= 0) {
        if (e.ancillary) fail('corrupt', 'section table', e.entry + 4, `${e.where}: ${e.tag} must be critical (Ancillary clear)`);
        if (critical !== nextCritical) fail('corrupt', 'section table', e.entry, `${e.where}: ${nextCritical < CRITICAL.length ? `expected ${CRITICAL[nextCritical]}` : `${e.tag} again`} (the critical sections come once each, in the order ${CRITICAL.join(', ')})`);
        ++nextCritical;
      } else if (e.tag === 'NOTE') {
        checkNote(e, notes++ > 0);
      } else if (!e.ancillary) {
        fail('reserved_bits_set', 'section table', e.entry, `${e.where}: unknown critical section`);
      }
    },
    end() {
      if (nextCritical < CRITICAL.length) fail('corrupt', 'section table', 24, `no ${CRITICAL[nextCritical]} section`);
    },
  };
}

// 9.1.1: CLIP, IMAG, SKEL at entries 0, 1, 2; after them at most one NOTE and unknown
// ancillary sections, in any order; nothing compressed; no section of the archive profile (in
// version 5, QUAT neither: 9.1.2).
export function runtimeRules(member = false, major = 4) {
  const SECTIONS = member ? withoutSkel(RUNTIME_SECTIONS) : RUNTIME_SECTIONS;
  const ARCHIVE_ONLY = (major >= 5 ? ARCHIVE_CRITICAL_5 : ARCHIVE_CRITICAL).filter((t) => !RUNTIME_SECTIONS.includes(t));
  let count = 0, notes = 0;
  return {
    entry(e) {
      ++count;
      if (member) refuseMemberSkel(e);
      if (e.compressed) fail('corrupt', 'section table', e.entry + 4, `${e.where}: no section of the runtime profile is compressed`);
      if (ARCHIVE_ONLY.includes(e.tag)) fail('corrupt', 'section table', e.entry, `${e.where}: the runtime profile holds no ${e.tag}`);
      if (e.index < SECTIONS.length) {
        const want = SECTIONS[e.index];
        if (e.tag !== want) fail('corrupt', 'section table', e.entry, `${e.where}: expected ${want} (the runtime profile's sections are ${SECTIONS.join(', ')} at entries 0 to ${SECTIONS.length - 1}, then NOTE or not)`);
        if (e.ancillary) fail('corrupt', 'section table', e.entry + 4, `${e.where}: ${e.tag} must be critical (Ancillary clear)`);
      } else if (SECTIONS.includes(e.tag)) {
        fail('corrupt', 'section table', e.entry, `${e.where}: ${e.tag} again`);
      } else if (e.tag === 'NOTE') {
        checkNote(e, notes++ > 0);
      } else if (!e.ancillary) {
        fail('reserved_bits_set', 'section table', e.entry, `${e.where}: unknown critical section`);
      }
    },
    end() {
      if (count < SECTIONS.length) fail('corrupt', 'section table', 24, `no ${SECTIONS[count]} section`);
    },
  };
}
