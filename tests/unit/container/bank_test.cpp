// Banks (spec/FORMAT.md section 10): write_bank of clips cut from data/'s two CMU files, in both
// profiles, with and without a dictionary; every clip of the bank samples bit for bit as its own
// file; clips of one skeleton share one rig, and the skeleton is stored once; find by name;
// a damaged clip fails by name while the others load; the rules of 10.1 to 10.5 broken one at a
// time, each refused with the spec's status.
//
// Offsets are computed here from the spec's tables (10.1 to 10.3), not from the library's
// bank_layout.h, and the XXH64 is xxHash's own.
#define XXH_INLINE_ALL
#include <xxhash.h>

#include <doctest/doctest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>
#include <vector>

#include "keyanim/bank.h"
#include "keyanim/offline/bank.h"
#include "keyanim/offline/bvh.h"
#include "keyanim/offline/container.h"
#include "keyanim/offline/decode.h"
#include "keyanim/offline/encode.h"
#include "keyanim/offline/error.h"

#include "le_bytes.h"

using keyanim::Bank;
using keyanim::Clip;
using keyanim::ErrorInfo;
using keyanim::Status;
namespace off = keyanim::offline;

namespace {

off::Motion cut(const off::Motion& m, uint32_t from, uint32_t count) {
  off::Motion c = m;
  c.frame_count = count;
  const size_t n = m.skeleton.channel_count();
  c.values.assign(m.values.begin() + std::ptrdiff_t(from * n), m.values.begin() + std::ptrdiff_t((from + count) * n));
  return c;
}

// Three clips of the walk's skeleton and one of the hop's, encoded with the default settings.
const std::vector<off::BankInput>& inputs() {
  static const std::vector<off::BankInput> in = [] {
    const off::Motion walk = off::read_bvh_file(KEYANIM_REPO_DATA_DIR "/cmu_02_01_walk.bvh");
    const off::Motion hop = off::read_bvh_file(KEYANIM_REPO_DATA_DIR "/cmu_131_03_hop.bvh");
    std::vector<off::BankInput> v;
    v.push_back({"walk/start", off::encode(cut(walk, 0, 40), {}).clip});
    v.push_back({"walk/middle", off::encode(cut(walk, 40, 90), {}).clip});
    v.push_back({"hop", off::encode(cut(hop, 0, 60), {}).clip});
    v.push_back({"walk", off::encode(cut(walk, 130, 1), {}).clip});
    return v;
  }();
  return in;
}

using container_test::get_le;
using container_test::put_le;

// Section 10.1's offsets, from the header.
struct Layout {
  uint64_t clips, skeletons, skeleton_table = 40, clip_table, name_order, names, checksum;
  explicit Layout(const std::vector<uint8_t>& b)
      : clips(get_le(b, 16, 4)), skeletons(get_le(b, 20, 4)), clip_table(40 + 32 * skeletons),
        name_order(clip_table + 40 * clips), names(name_order + 4 * clips),
        checksum(get_le(b, clip_table, 8) - 8) {}  // the first member follows the checksum
  uint64_t clip(uint64_t i) const { return clip_table + 40 * i; }
};

void fix_checksum(std::vector<uint8_t>& b) {
  const Layout l(b);
  put_le(b, l.checksum, 8, XXH64(b.data(), l.checksum, 0));
}

Status open_fails(const std::vector<uint8_t>& b, ErrorInfo* err = nullptr) {
  Bank bank;
  const Status s = Bank::open(b, bank, err);
  if (s != Status::ok) CHECK(bank.clip_count() == 0);
  return s;
}

bool same_values(const Clip& a, const Clip& b) {
  const off::Motion x = off::decode_motion(a), y = off::decode_motion(b);
  return x.values.size() == y.values.size() &&
         std::memcmp(x.values.data(), y.values.data(), x.values.size() * sizeof(double)) == 0;
}

void check_bank_clips(const off::WrittenBank& w, bool runtime) {
  Bank bank;
  REQUIRE(Bank::open(w.bytes, bank) == Status::ok);
  CHECK(bank.clip_count() == inputs().size());
  CHECK(bank.skeleton_count() == 2);
  CHECK(w.skeletons == 2);
  CHECK(bank.runtime_profile() == runtime);
  std::vector<Clip> clips(inputs().size());
  for (uint32_t i = 0; i < bank.clip_count(); ++i) {
    const off::BankInput& in = inputs()[i];
    CAPTURE(in.name);
    REQUIRE(bank.clip(i, clips[i]) == Status::ok);
    CHECK(clips[i].runtime_profile() == runtime);
    Clip own;
    REQUIRE(Clip::load(off::write_kanim(in.clip), own) == Status::ok);
    CHECK(same_values(clips[i], own));
    CHECK(bank.find(in.name) == i);
    const keyanim::BankEntry e = bank.entry(i);
    CHECK(e.name == in.name);
    CHECK(e.frame_count == in.clip.frame_count);
    CHECK(e.frame_time == in.clip.frame_time);
  }
  CHECK(!bank.find("walk/").has_value());
  CHECK(!bank.find("").has_value());
  CHECK(clips[0].shares_rig(clips[1]));
  CHECK(clips[0].shares_rig(clips[3]));
  CHECK(!clips[0].shares_rig(clips[2]));
}

}  // namespace

TEST_SUITE("bank") {

TEST_CASE("a bank's clips sample as their own files, in both profiles, with and without a dictionary") {
  for (auto dict : {off::BankDictionary::never, off::BankDictionary::always, off::BankDictionary::automatic}) {
    CAPTURE(int(dict));
    off::BankOptions o;
    o.dictionary = dict;
    const off::WrittenBank w = off::write_bank(inputs(), o);
    CHECK((w.dictionary_bytes > 0) == (dict == off::BankDictionary::always));
    if (w.dictionary_bytes > 0) CHECK(get_le(w.bytes, 40 + 32 + 0, 4) != 0);
    check_bank_clips(w, false);
  }
  off::BankOptions o;
  o.runtime = true;
  check_bank_clips(off::write_bank(inputs(), o), true);
}

TEST_CASE("a zstd context kept from the thread's earlier files changes no byte") {
  // write_kanim and write_bank keep their zstd context for the next file on the thread. The
  // files of a fresh thread (no context kept) are the reference; here, after other clips and
  // a bank with a dictionary, the same clip and bank give the same bytes.
  const off::EncodedClip& clip = inputs()[0].clip;
  off::BankOptions with_dictionary;
  with_dictionary.dictionary = off::BankDictionary::always;
  std::vector<uint8_t> fresh_file, fresh_bank;
  std::thread([&] { fresh_file = off::write_kanim(clip); }).join();
  std::thread([&] { fresh_bank = off::write_bank(inputs(), with_dictionary).bytes; }).join();
  const off::WrittenBank bank = off::write_bank(inputs(), with_dictionary);
  REQUIRE(bank.dictionary_bytes > 0);
  CHECK(bank.bytes == fresh_bank);
  (void)off::write_kanim(inputs()[2].clip, 3);  // another clip at another level
  CHECK(off::write_kanim(clip) == fresh_file);  // after a dictionary and another level
  CHECK(off::write_bank(inputs(), with_dictionary).bytes == fresh_bank);
}

TEST_CASE("the skeleton is stored once") {
  // Each walk clip's own file holds the walk's SKEL (compressed); the bank holds it once, as it is.
  const off::Motion walk = off::read_bvh_file(KEYANIM_REPO_DATA_DIR "/cmu_02_01_walk.bvh");
  std::vector<off::BankInput> in;
  size_t own = 0;
  for (uint32_t k = 0; k < 8; ++k) {
    in.push_back({"w" + std::to_string(k), off::encode(cut(walk, 20 * k, 20), {}).clip});
    own += off::write_kanim(in.back().clip).size();
  }
  off::BankOptions o;
  o.dictionary = off::BankDictionary::never;
  const off::WrittenBank plain = off::write_bank(in, o);
  o.dictionary = off::BankDictionary::automatic;
  const off::WrittenBank best = off::write_bank(in, o);
  MESSAGE("8 clips of 20 frames: own files " << own << " bytes, bank " << plain.bytes.size() << ", with a dictionary "
                                               << best.bytes.size() << " (dictionary " << best.dictionary_bytes << ")");
  CHECK(plain.skeletons == 1);
  CHECK(plain.bytes.size() < own);
  CHECK(best.bytes.size() <= plain.bytes.size());
  if (best.dictionary_bytes > 0) CHECK(best.bytes_without_dictionary == plain.bytes.size());
}

TEST_CASE("runtime clips are sampled where they lie in a viewed bank") {
  off::BankOptions o;
  o.runtime = true;
  const off::WrittenBank w = off::write_bank(inputs(), o);
  std::vector<uint64_t> words(w.bytes.size() / 8 + 1);
  std::memcpy(words.data(), w.bytes.data(), w.bytes.size());
  const std::span<const uint8_t> in_place(reinterpret_cast<const uint8_t*>(words.data()), w.bytes.size());
  Bank viewed, owned, misaligned;
  REQUIRE(Bank::view(in_place, viewed) == Status::ok);
  REQUIRE(Bank::open(w.bytes, owned) == Status::ok);
  CHECK(Bank::view(in_place.subspan(1), misaligned) == Status::invalid_argument);
  Clip a, b;
  REQUIRE(viewed.clip(2, a) == Status::ok);
  REQUIRE(owned.clip(2, b) == Status::ok);
  CHECK(same_values(a, b));
  CHECK(viewed.entry(2).offset % 8 == 0);
  // A viewed bank reads the caller's bytes in place (here its index: clip 2's name).
  const uint64_t name_at = Layout(w.bytes).names + get_le(w.bytes, Layout(w.bytes).clip(2) + 32, 4);
  reinterpret_cast<uint8_t*>(words.data())[name_at] = 'X';
  CHECK(viewed.entry(2).name == "Xop");
  CHECK(owned.entry(2).name == "hop");
  // An opened bank's clip keeps the bank's bytes alive: it outlives the bank.
  owned = Bank{};
  std::vector<float> x(b.channel_count()), y(b.channel_count());
  CHECK(b.sample(10.5, x) == Status::ok);
  CHECK(a.sample(10.5, y) == Status::ok);
  CHECK(std::memcmp(x.data(), y.data(), x.size() * sizeof(float)) == 0);
}

TEST_CASE("open_file maps regular files only: a FIFO is refused without waiting for a writer") {
  char dir[] = "/tmp/keyanim_bank_test.XXXXXX";
  REQUIRE(::mkdtemp(dir) != nullptr);
  const std::string fifo = std::string(dir) + "/pipe.kbank";
  REQUIRE(::mkfifo(fifo.c_str(), 0600) == 0);
  Bank b;
  ErrorInfo err;
  CHECK(Bank::open_file(fifo, b, &err) == Status::io_error);  // a hang here: open() without O_NONBLOCK
  CHECK(err.detail.find("not a regular file") != std::string::npos);
  CHECK(Bank::open_file("/dev/zero", b, &err) == Status::io_error);
  CHECK(b.clip_count() == 0);
  ::unlink(fifo.c_str());
  ::rmdir(dir);
}

TEST_CASE("a damaged clip fails by its name, and the others still load") {
  off::BankOptions o;
  o.dictionary = off::BankDictionary::always;
  std::vector<uint8_t> b = off::write_bank(inputs(), o).bytes;
  const Layout l(b);
  b.at(get_le(b, l.clip(1), 8) + get_le(b, l.clip(1) + 8, 8) - 10) ^= 0x20;  // in its last section
  Bank bank;
  REQUIRE(Bank::open(b, bank) == Status::ok);  // the index is intact
  Clip clip;
  ErrorInfo err;
  CHECK(bank.clip(1, clip, &err) == Status::checksum_mismatch);
  CHECK(err.section.find("walk/middle") != std::string::npos);
  CHECK(err.byte_offset >= get_le(b, l.clip(1), 8));
  CHECK(clip.channel_count() == 0);
  for (uint32_t i : {0u, 2u, 3u}) CHECK(bank.clip(i, clip) == Status::ok);
}

TEST_CASE("the rules of section 10, broken one at a time") {
  off::BankOptions o;
  o.dictionary = off::BankDictionary::never;
  const std::vector<uint8_t> good = off::write_bank(inputs(), o).bytes;
  REQUIRE(open_fails(good) == Status::ok);
  const Layout l(good);
  auto broken = [&](auto change, bool fix = true) {
    std::vector<uint8_t> b = good;
    change(b);
    if (fix) fix_checksum(b);
    ErrorInfo err;
    const Status s = open_fails(b, &err);
    CHECK(err.status == s);
    return s;
  };
  SUBCASE("a clip is not a bank, a bank is not a clip") {
    Clip clip;
    CHECK(Clip::load(good, clip) == Status::invalid_argument);
    CHECK(open_fails(off::write_kanim(inputs()[0].clip)) == Status::invalid_argument);
  }
  SUBCASE("every truncation, appended bytes, and the checksum") {
    for (size_t n = 0; n < good.size(); n += (n < 4096 ? 1 : 97)) {
      CAPTURE(n);
      CHECK(open_fails({good.begin(), good.begin() + std::ptrdiff_t(n)}) == Status::truncated);
    }
    std::vector<uint8_t> longer = good;
    longer.push_back(0);
    CHECK(open_fails(longer) == Status::trailing_bytes);
    for (uint64_t i = 40; i < l.checksum; ++i) {  // the index, names, skeletons (not the header's counts)
      std::vector<uint8_t> b = good;
      b[i] ^= 0x01;
      CHECK(open_fails(b) != Status::ok);
    }
  }
  SUBCASE("every bit flip of a member fails that clip, by its name, and only that clip") {
    Bank bank;
    Clip clip;
    ErrorInfo err;
    for (uint32_t c = 0; c < l.clips; ++c) {
      const uint64_t from = get_le(good, l.clip(c), 8), size = get_le(good, l.clip(c) + 8, 8);
      const std::string name(reinterpret_cast<const char*>(&good[l.names + get_le(good, l.clip(c) + 32, 4)]),
                             get_le(good, l.clip(c) + 36, 4));
      for (uint64_t i = from; i < from + size; ++i) {
        std::vector<uint8_t> b = good;
        b[i] ^= uint8_t(1u << (i % 8));
        CAPTURE(i);
        REQUIRE(Bank::open(b, bank) == Status::ok);  // the index is intact
        CHECK(bank.clip(c, clip, &err) != Status::ok);
        CHECK(err.section.find("clip " + name + " (") != std::string::npos);
        for (uint32_t k = 0; k < l.clips; ++k)
          if (k != c) CHECK(bank.clip(k, clip) == Status::ok);
      }
    }
  }
  SUBCASE("header") {
    CHECK(broken([](auto& b) { put_le(b, 8, 2, 6); }) == Status::unsupported_version);
    CHECK(broken([](auto& b) { b[12] |= 0x08; }) == Status::reserved_bits_set);
    CHECK(broken([](auto& b) { b[12] |= 0x02; }) == Status::corrupt);  // Member set in a bank
  }
  SUBCASE("2^32 - 1 declared clips are refused from the header, before anything is allocated") {
    CHECK(broken([](auto& b) { put_le(b, 16, 4, 0xFFFFFFFFu); }, false) == Status::truncated);
    CHECK(broken([](auto& b) { put_le(b, 20, 4, 0xFFFFFFFFu); }, false) == Status::truncated);
    CHECK(broken([](auto& b) { put_le(b, 24, 8, ~uint64_t(0)); }, false) == Status::truncated);
    CHECK(broken([](auto& b) { put_le(b, 32, 8, ~uint64_t(0) - 3); }, false) == Status::truncated);
  }
  SUBCASE("a clip outside the bank, overlapping clips, a gap") {
    CHECK(broken([&](auto& b) { put_le(b, l.clip(3) + 8, 8, 1u << 30); }) == Status::truncated);
    CHECK(broken([&](auto& b) { put_le(b, l.clip(1), 8, get_le(b, l.clip(0), 8)); }) == Status::corrupt);
    CHECK(broken([&](auto& b) { put_le(b, l.clip(1), 8, get_le(b, l.clip(1), 8) + 8); }) == Status::corrupt);
    {  // a member one byte short: the next still starts where 10.1 says; the byte cut off is now
       // padding before clip 1, which is not zero: those two fail, the others load
      std::vector<uint8_t> b = good;
      put_le(b, l.clip(0) + 8, 8, get_le(b, l.clip(0) + 8, 8) - 1);
      fix_checksum(b);
      Bank bank;
      Clip clip;
      if (Bank::open(b, bank) == Status::ok) {
        CHECK(bank.clip(0, clip) == Status::truncated);
        CHECK(bank.clip(1, clip) == Status::corrupt);
        CHECK(bank.clip(2, clip) == Status::ok);
      }
    }
    CHECK(broken([&](auto& b) { put_le(b, l.skeleton_table, 8, 0); }) == Status::corrupt);
  }
  SUBCASE("names: two clips of one name, '..', an empty part, a byte 0, the order") {
    // "walk/start" (clip 0) and "walk" (clip 3): clip 0's name cut to clip 3's length.
    CHECK(broken([&](auto& b) { put_le(b, l.clip(0) + 36, 4, 4); }) == Status::corrupt);
    auto rename = [&](const std::string& n) {
      return broken([&](auto& b) { std::memcpy(b.data() + l.names + get_le(b, l.clip(0) + 32, 4), n.data(), n.size()); });
    };
    CHECK(rename("walk/../a.") == Status::corrupt);
    CHECK(rename("walk//star") == Status::corrupt);
    CHECK(rename(std::string("walk\0start", 10)) == Status::corrupt);
    CHECK(rename("/alk/start") == Status::corrupt);
    CHECK(broken([&](auto& b) { put_le(b, l.name_order, 4, get_le(b, l.name_order + 4, 4)); }) == Status::corrupt);
    CHECK(broken([&](auto& b) { put_le(b, l.name_order, 4, 4); }) == Status::corrupt);
    CHECK(broken([&](auto& b) { put_le(b, l.clip(2) + 28, 4, 2); }) == Status::corrupt);  // skeleton 2 of 2
  }
  SUBCASE("padding") {
    const uint64_t end = l.names + get_le(good, 24, 8);
    if (end % 8 != 0) CHECK(broken([&](auto& b) { b[end] = 1; }) == Status::corrupt);
  }
  SUBCASE("the writer refuses what a reader would") {
    std::vector<off::BankInput> in = {inputs()[0], inputs()[0]};
    CHECK_THROWS_AS(off::write_bank(in), off::Error);
    in[1].name = "a/../b";
    CHECK_THROWS_AS(off::write_bank(in), off::Error);
    in[1].name = "";
    CHECK_THROWS_AS(off::write_bank(in), off::Error);
  }
}

TEST_CASE("a dictionary whose entropy tables do not decode is corrupt (fuzz_bank)") {
  // zstd refuses such a dictionary as it would refuse memory; the bank said "out of memory"
  // (limit_exceeded) for it (corpus/bank/crash-dictionary-tables.kbank).
  off::BankOptions o;
  o.dictionary = off::BankDictionary::always;
  std::vector<uint8_t> b = off::write_bank(inputs(), o).bytes;
  const Layout l(b);
  const uint64_t dict = (l.names + get_le(b, 24, 8) + 7) / 8 * 8, dict_size = get_le(b, 32, 8);
  REQUIRE(dict_size > 8 + 65);
  REQUIRE(get_le(b, dict, 4) == 0xEC30A437u);
  // After the magic and the dictionary ID, the literals' Huffman table: a header byte of 255
  // says 128 weights in 4 bits each, and weights of 15 exceed any table zstd decodes.
  for (uint64_t i = dict + 8; i < dict + 8 + 65; ++i) b[i] = 0xFF;
  fix_checksum(b);
  ErrorInfo err;
  CHECK(open_fails(b, &err) == Status::corrupt);
  CHECK(err.section == "dictionary");
  CHECK(err.byte_offset == dict);
}

TEST_CASE("a member's own rules (10.5)") {
  off::BankOptions o;
  o.dictionary = off::BankDictionary::never;
  const std::vector<uint8_t> good = off::write_bank(inputs(), o).bytes;
  const Layout l(good);
  const uint64_t m = get_le(good, l.clip(0), 8), size = get_le(good, l.clip(0) + 8, 8);
  const std::vector<uint8_t> member(good.begin() + std::ptrdiff_t(m), good.begin() + std::ptrdiff_t(m + size));
  Clip clip;
  CHECK(Clip::load(member, clip) == Status::corrupt);  // Member set: read only through its bank
  // Frame_Count in the clip table against CLIP's.
  std::vector<uint8_t> b = good;
  put_le(b, l.clip(0) + 24, 4, get_le(b, l.clip(0) + 24, 4) + 1);
  fix_checksum(b);
  Bank bank;
  REQUIRE(Bank::open(b, bank) == Status::ok);
  ErrorInfo err;
  CHECK(bank.clip(0, clip, &err) == Status::corrupt);
  CHECK(err.section.find("walk/start") != std::string::npos);
  CHECK(err.byte_offset == l.clip(0) + 24);  // the field itself (spec section 7's offsets)
  CHECK(bank.clip(1, clip) == Status::ok);
  // Frame_Time likewise, at its own offset.
  b = good;
  b[l.clip(1) + 16] ^= 0x01;
  fix_checksum(b);
  REQUIRE(Bank::open(b, bank) == Status::ok);
  CHECK(bank.clip(1, clip, &err) == Status::corrupt);
  CHECK(err.byte_offset == l.clip(1) + 16);
  CHECK(err.detail.find("Frame_Time") != std::string::npos);
  CHECK(bank.clip(4, clip) == Status::invalid_argument);
  // The bank says the runtime profile, its members the archive's.
  b = good;
  b[12] |= 0x01;
  fix_checksum(b);
  REQUIRE(Bank::open(b, bank) == Status::ok);
  CHECK(bank.clip(1, clip) == Status::corrupt);
}

}  // TEST_SUITE

TEST_SUITE("bank") {

// spec/test-vectors/b41_*.kbank (Appendix C): each clip decodes as the vector it is named after,
// bit for bit; in b41_damaged, clip v3_uniform fails its checksum and the others decode.
TEST_CASE("the bank vectors decode as the vectors their clips are named after") {
  for (const char* v : {"b41_archive", "b41_dictionary", "b41_runtime", "b41_damaged"}) {
    CAPTURE(v);
    std::ifstream in(std::string(KEYANIM_SPEC_DIR "/test-vectors/") + v + ".kbank", std::ios::binary);
    const std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    Bank bank;
    REQUIRE(Bank::open(bytes, bank) == Status::ok);
    CHECK(bank.clip_count() == (std::string(v) == "b41_runtime" ? 6u : 7u));
    CHECK(bank.runtime_profile() == (std::string(v) == "b41_runtime"));
    CHECK((bank.dictionary_bytes() > 0) == (std::string(v) == "b41_dictionary"));
    for (uint32_t i = 0; i < bank.clip_count(); ++i) {
      const std::string name(bank.entry(i).name);
      CAPTURE(name);
      Clip clip, own;
      if (std::string(v) == "b41_damaged" && name == "v3_uniform") {
        CHECK(bank.clip(i, clip) == Status::checksum_mismatch);
        continue;
      }
      REQUIRE(bank.clip(i, clip) == Status::ok);
      std::ifstream f(std::string(KEYANIM_SPEC_DIR "/test-vectors/") + name + ".kanim", std::ios::binary);
      const std::vector<uint8_t> file((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
      REQUIRE(Clip::load(file, own) == Status::ok);
      CHECK(same_values(clip, own));
    }
  }
}

}  // TEST_SUITE
