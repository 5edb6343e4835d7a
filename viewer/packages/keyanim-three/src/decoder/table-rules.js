// What each profile allows in the section table: rules 3.2.2 and 3.2.3 (archive) and 9.1.1
// (runtime). Each returns { entry(e), end() }, called per table entry (e: index, tag,
// compressed, ancillary, entry = the entry's file offset, where = its name for messages) and
// once after the last; they throw KanimError.
import { fail } from './errors.js';

const ARCHIVE_CRITICAL = ['CLIP', 'SKEL', 'CHAN', 'KTIM', 'KVAL'];
const RUNTIME_SECTIONS = ['CLIP', 'IMAG', 'SKEL'];

// NOTE: at most once, ancillary (3.2.3; 9.1.2 keeps it in the runtime profile).
function checkNote(e, seen) {
  if (!e.ancillary) fail('corrupt', 'section table', e.entry + 4, `${e.where}: NOTE must be ancillary`);
  if (seen) fail('corrupt', 'section table', e.entry, `${e.where}: a second NOTE section`);
}

export function archiveRules() {
  let nextCritical = 0, notes = 0;
  return {
    entry(e) {
      const critical = ARCHIVE_CRITICAL.indexOf(e.tag);
      if (critical >= 0) {
        if (e.ancillary) fail('corrupt', 'section table', e.entry + 4, `${e.where}: ${e.tag} must be critical (Ancillary clear)`);
        if (critical !== nextCritical) fail('corrupt', 'section table', e.entry, `${e.where}: ${nextCritical < ARCHIVE_CRITICAL.length ? `expected ${ARCHIVE_CRITICAL[nextCritical]}` : `${e.tag} again`} (the critical sections come once each, in the order ${ARCHIVE_CRITICAL.join(', ')})`);
        ++nextCritical;
      } else if (e.tag === 'NOTE') {
        checkNote(e, notes++ > 0);
      } else if (!e.ancillary) {
        fail('reserved_bits_set', 'section table', e.entry, `${e.where}: unknown critical section`);
      }
    },
    end() {
      if (nextCritical < ARCHIVE_CRITICAL.length) fail('corrupt', 'section table', 24, `no ${ARCHIVE_CRITICAL[nextCritical]} section`);
    },
  };
}

// 9.1.1: CLIP, IMAG, SKEL at entries 0, 1, 2; after them at most one NOTE and unknown
// ancillary sections, in any order; nothing compressed; no section of the archive profile.
export function runtimeRules() {
  let count = 0, notes = 0;
  return {
    entry(e) {
      ++count;
      if (e.compressed) fail('corrupt', 'section table', e.entry + 4, `${e.where}: no section of the runtime profile is compressed`);
      if (ARCHIVE_CRITICAL.includes(e.tag) && !RUNTIME_SECTIONS.includes(e.tag)) fail('corrupt', 'section table', e.entry, `${e.where}: the runtime profile holds no ${e.tag}`);
      if (e.index < RUNTIME_SECTIONS.length) {
        const want = RUNTIME_SECTIONS[e.index];
        if (e.tag !== want) fail('corrupt', 'section table', e.entry, `${e.where}: expected ${want} (the runtime profile's sections are CLIP, IMAG, SKEL at entries 0 to 2, then NOTE or not)`);
        if (e.ancillary) fail('corrupt', 'section table', e.entry + 4, `${e.where}: ${e.tag} must be critical (Ancillary clear)`);
      } else if (RUNTIME_SECTIONS.includes(e.tag)) {
        fail('corrupt', 'section table', e.entry, `${e.where}: ${e.tag} again`);
      } else if (e.tag === 'NOTE') {
        checkNote(e, notes++ > 0);
      } else if (!e.ancillary) {
        fail('reserved_bits_set', 'section table', e.entry, `${e.where}: unknown critical section`);
      }
    },
    end() {
      if (count < RUNTIME_SECTIONS.length) fail('corrupt', 'section table', 24, `no ${RUNTIME_SECTIONS[count]} section`);
    },
  };
}
