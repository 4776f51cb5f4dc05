#pragma once
// Implementation of the checkpoint format, generic over the particle type so a test can prove that any
// field list round-trips. Include only from checkpoint.cpp and tests.
#include <algorithm>
#include <bit>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "cellsph/core/atomic_file.hpp"
#include "cellsph/core/error.hpp"
#include "cellsph/io/checkpoint.hpp"

namespace cellsph {

static_assert(std::endian::native == std::endian::little, "checkpoints are written little endian");

namespace io::detail {

inline constexpr char kMagic[8] = {'C', 'S', 'P', 'H', 'C', 'K', 'P', 'T'};
inline constexpr std::uint32_t kByteOrderMark = 0x01020304u;

// FNV-1a over 64-bit words (the tail zero-padded): 8x fewer dependent multiplies than the byte-wise
// hash, enough to detect a corrupted or half-written file.
inline std::uint64_t checksum(const char* data, std::size_t n) {
  std::uint64_t h = 0xcbf29ce484222325ull;
  constexpr std::uint64_t prime = 0x100000001b3ull;
  std::size_t i = 0;
  for (; i + 8 <= n; i += 8) {
    std::uint64_t w;
    std::memcpy(&w, data + i, 8);
    h = (h ^ w) * prime;
  }
  if (i < n) {
    std::uint64_t w = 0;
    std::memcpy(&w, data + i, n - i);
    h = (h ^ w) * prime;
  }
  return (h ^ n) * prime;
}

template <class T>
void put(std::string& out, const T& v) {
  static_assert(std::is_trivially_copyable_v<T>);
  out.append(reinterpret_cast<const char*>(&v), sizeof(T));
}

inline void put_string(std::string& out, std::string_view s, bool short_len) {
  if (short_len)
    put(out, static_cast<std::uint32_t>(s.size()));
  else
    put(out, static_cast<std::uint64_t>(s.size()));
  out.append(s);
}

// Bounds-checked reader over the file's bytes; every failure names the file and what was read.
class Cursor {
 public:
  Cursor(const std::filesystem::path& path, const std::string& bytes, std::size_t end)
      : path_(path), bytes_(bytes), end_(end) {}

  [[noreturn]] void fail(const std::string& what) const {
    throw InputError("checkpoint '" + path_.string() + "': " + what);
  }
  void need(std::size_t n, std::string_view what) const {
    if (n > end_ - pos_)
      fail("truncated: file ends at byte " + std::to_string(end_) + " while reading " + std::string(what) +
           " (needs " + std::to_string(n) + " bytes at byte " + std::to_string(pos_) + ")");
  }
  template <class T>
  T get(std::string_view what) {
    need(sizeof(T), what);
    T v;
    std::memcpy(&v, bytes_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return v;
  }
  std::string_view get_bytes(std::size_t n, std::string_view what) {
    need(n, what);
    std::string_view s(bytes_.data() + pos_, n);
    pos_ += n;
    return s;
  }
  [[nodiscard]] std::string_view peek(std::size_t n) const {
    return {bytes_.data() + pos_, std::min(n, end_ - pos_)};
  }
  [[nodiscard]] std::size_t pos() const { return pos_; }

 private:
  const std::filesystem::path& path_;
  const std::string& bytes_;
  std::size_t end_;
  std::size_t pos_ = 0;
};

inline std::string read_all(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError("cannot read checkpoint '" + path.string() + "'");
  std::string bytes;
  in.seekg(0, std::ios::end);
  const auto size = in.tellg();
  if (size < 0) throw InputError("cannot read checkpoint '" + path.string() + "'");
  bytes.resize(static_cast<std::size_t>(size));
  in.seekg(0);
  in.read(bytes.data(), size);
  if (!in) throw InputError("error while reading checkpoint '" + path.string() + "'");
  return bytes;
}

inline CheckpointHeader parse_header(Cursor& c) {
  // A short file that does not even start like a checkpoint is "not a checkpoint", not "truncated".
  const auto head = c.peek(sizeof(kMagic));
  if (std::memcmp(head.data(), kMagic, head.size()) != 0)
    c.fail("bad magic number: not a cellsph checkpoint");
  const auto magic = c.get_bytes(sizeof(kMagic), "the magic number");
  if (std::memcmp(magic.data(), kMagic, sizeof(kMagic)) != 0)
    c.fail("bad magic number: not a cellsph checkpoint");
  CheckpointHeader h;
  h.version = c.get<std::uint32_t>("the format version");
  if (h.version < kCheckpointOldestVersion || h.version > kCheckpointVersion)
    c.fail("format version " + std::to_string(h.version) + " is not supported (this build reads versions " +
           std::to_string(kCheckpointOldestVersion) + " to " + std::to_string(kCheckpointVersion) + ")");
  if (c.get<std::uint32_t>("the byte-order mark") != kByteOrderMark)
    c.fail("byte-order mark mismatch (written on a machine of other endianness, or corrupted)");
  h.dim = static_cast<int>(c.get<std::uint32_t>("the dimension"));
  h.real_size = static_cast<int>(c.get<std::uint32_t>("the precision"));
  h.count = c.get<std::uint64_t>("the particle count");
  h.time = c.get<double>("the simulated time");
  h.step = c.get<std::uint64_t>("the step count");
  return h;
}

inline const char* precision_name(int size) {
  return size == 4 ? "float" : size == 8 ? "double" : "unknown";
}

}  // namespace io::detail

// The fields of a checkpoint as one list: the particles' fields, then the solver state's. P is Particles or
// a const reference to them (writing), S likewise.
template <class P, class S>
struct CheckpointFields {
  using V = typename std::remove_cvref_t<P>::V;
  P particles;
  S state;

  template <class Self, class F>
  static void for_each_field(Self& self, F&& fn) {
    std::remove_cvref_t<P>::for_each_field(self.particles, fn);
    std::remove_cvref_t<S>::for_each_field(self.state, fn);
  }
  template <class F>
  void for_each_field(F&& fn) {
    for_each_field(*this, fn);
  }
  template <class F>
  void for_each_field(F&& fn) const {
    for_each_field(*this, fn);
  }
  [[nodiscard]] std::size_t size() const { return particles.size(); }
  void resize(std::size_t n) {
    for_each_field([n](std::string_view, auto& field) { field.resize(n); });
  }
  // Fields a file of `version` may lack (then left at 0): the solver state came with version 2.
  [[nodiscard]] bool absent_before(std::string_view name, std::uint32_t version) const {
    bool state_field = false;
    std::remove_cvref_t<S>::for_each_field(
        state, [&](std::string_view n, const auto&) { state_field = state_field || n == name; });
    return state_field && version < 2;
  }
};

// Generic over the particle type (a vector type V, size(), resize(), for_each_field(), and optionally
// absent_before(name, version) for fields older versions lack); the public functions instantiate them for
// CheckpointFields, tests for an extended field list.
template <class P>
void write_checkpoint_any(const P& particles, const CheckpointInfo& info, const std::filesystem::path& path) {
  using namespace io::detail;
  using V = typename P::V;
  constexpr int Dim = V::dim;
  using Real = typename V::scalar;
  std::string out;
  std::size_t bytes = 256 + info.user.size();
  particles.for_each_field([&](std::string_view name, const auto& field) {
    bytes += 16 + name.size() + field.size() * sizeof(field[0]);
  });
  out.reserve(bytes);
  out.append(kMagic, sizeof(kMagic));
  put(out, kCheckpointVersion);
  put(out, kByteOrderMark);
  put(out, static_cast<std::uint32_t>(Dim));
  put(out, static_cast<std::uint32_t>(sizeof(Real)));
  put(out, static_cast<std::uint64_t>(particles.size()));
  put(out, info.time);
  put(out, info.step);
  put_string(out, info.user, false);
  std::uint32_t nfields = 0;
  particles.for_each_field([&](std::string_view, const auto&) { ++nfields; });
  put(out, nfields);
  particles.for_each_field([&](std::string_view name, const auto& field) {
    using T = typename std::remove_cvref_t<decltype(field)>::value_type;
    static_assert(std::is_trivially_copyable_v<T>, "checkpointed fields must be trivially copyable");
    CELLSPH_CHECK(field.size() == particles.size(), "field '" << name << "' has " << field.size()
                                                              << " elements for " << particles.size()
                                                              << " particles");
    put_string(out, name, true);
    put(out, static_cast<std::uint32_t>(sizeof(T)));
    put(out, static_cast<std::uint64_t>(field.size()));
    if (!field.empty()) out.append(reinterpret_cast<const char*>(field.data()), field.size() * sizeof(T));
  });
  put(out, checksum(out.data(), out.size()));
  write_file_atomic(path, out);
}

namespace io::detail {

// The header's dimension and precision must be the run's.
template <int Dim, class Real>
void check_same_kind_of_run(const Cursor& c, const CheckpointHeader& h) {
  if (h.dim != Dim)
    c.fail("written by a " + std::to_string(h.dim) + "D run, cannot continue a " + std::to_string(Dim) +
           "D run");
  if (h.real_size != static_cast<int>(sizeof(Real)))
    c.fail(std::string("precision mismatch: file holds ") + precision_name(h.real_size) + " (" +
           std::to_string(h.real_size) + " bytes), this run uses " + precision_name(sizeof(Real)));
}

// Before allocating: a corrupt count must not ask for more memory than the file (up to `body`, where the
// checksum starts) could fill.
template <class P>
void check_count_fits(const Cursor& c, const P& particles, const CheckpointHeader& h, std::size_t body) {
  std::size_t per_particle = 0;
  particles.for_each_field([&](std::string_view name, const auto& field) {
    if constexpr (requires { particles.absent_before(name, h.version); })
      if (particles.absent_before(name, h.version)) return;
    per_particle += sizeof(field[0]);
  });
  if (per_particle && h.count > (body - c.pos()) / per_particle)
    c.fail("truncated or corrupt: " + std::to_string(h.count) +
           " particles need more bytes than the file has");
}

// One field's element size, count and data, after its name, into the field of `loaded` of that name.
template <class P>
void read_field(Cursor& c, P& loaded, const std::string& name, const CheckpointHeader& h, std::size_t body) {
  const auto elem_size = c.get<std::uint32_t>("the element size of field '" + name + "'");
  const auto count = c.get<std::uint64_t>("the element count of field '" + name + "'");
  bool found = false;
  loaded.for_each_field([&](std::string_view fname, auto& field) {
    if (fname != name) return;
    found = true;
    using T = typename std::remove_cvref_t<decltype(field)>::value_type;
    if (elem_size != sizeof(T))
      c.fail("field '" + name + "' has elements of " + std::to_string(elem_size) + " bytes, expected " +
             std::to_string(sizeof(T)));
    if (count != h.count)
      c.fail("field '" + name + "' has " + std::to_string(count) + " elements for " +
             std::to_string(h.count) + " particles");
    if (count > (body - c.pos()) / sizeof(T))  // checked by division: a corrupt count must not overflow
      c.fail("truncated: file ends at byte " + std::to_string(body) + " inside the data of field '" + name +
             "'");
    const auto data =
        c.get_bytes(static_cast<std::size_t>(count) * sizeof(T), "the data of field '" + name + "'");
    if (count) std::memcpy(field.data(), data.data(), data.size());
  });
  CELLSPH_CHECK(found, name);
}

// The field count and the fields, into `loaded` (sized to the header's count). Each field of `loaded` must
// be there once, unless the file's version predates it; no other field may be.
template <class P>
void read_fields(Cursor& c, P& loaded, const CheckpointHeader& h, std::size_t body) {
  std::set<std::string, std::less<>> known, seen;
  loaded.for_each_field([&](std::string_view name, const auto&) { known.emplace(name); });
  const auto nfields = c.get<std::uint32_t>("the field count");
  for (std::uint32_t fi = 0; fi < nfields; ++fi) {
    const auto what = "field " + std::to_string(fi + 1) + " of " + std::to_string(nfields);
    const auto name_len = c.get<std::uint32_t>(what + " (name length)");
    const std::string name(c.get_bytes(name_len, what + " (name)"));
    if (!known.count(name))
      c.fail("unknown field '" + name + "' (" + what + "); this build does not have it");
    if (!seen.insert(name).second) c.fail("field '" + name + "' appears twice");
    read_field(c, loaded, name, h, body);
  }
  for (const auto& name : known) {
    if (seen.count(name)) continue;
    if constexpr (requires { loaded.absent_before(name, h.version); })
      if (loaded.absent_before(name, h.version)) continue;  // 0, as resize left it
    c.fail("missing field '" + name + "'");
  }
}

}  // namespace io::detail

template <class P>
CheckpointInfo read_checkpoint_any(const std::filesystem::path& path, P& particles) {
  using namespace io::detail;
  using V = typename P::V;
  const std::string bytes = read_all(path);
  if (bytes.size() < sizeof(std::uint64_t) + sizeof(kMagic)) {
    Cursor c(path, bytes, bytes.size());
    parse_header(c);  // reports bad magic or truncation
  }
  // The checksum is the last 8 bytes: everything before it is the body.
  const std::size_t body = bytes.size() - sizeof(std::uint64_t);
  Cursor c(path, bytes, body);
  const CheckpointHeader h = parse_header(c);
  check_same_kind_of_run<V::dim, typename V::scalar>(c, h);
  CheckpointInfo info;
  info.time = h.time;
  info.step = h.step;
  const auto user_len = c.get<std::uint64_t>("the user data length");
  info.user = std::string(c.get_bytes(user_len, "the user data"));

  check_count_fits(c, particles, h, body);
  P loaded;
  loaded.resize(static_cast<std::size_t>(h.count));
  read_fields(c, loaded, h, body);
  if (c.pos() != body)
    c.fail(std::to_string(body - c.pos()) +
           " unexpected bytes after the last field (corrupted or wrong format)");
  std::uint64_t stored;
  std::memcpy(&stored, bytes.data() + body, sizeof(stored));
  if (stored != checksum(bytes.data(), body)) c.fail("checksum mismatch: the file is corrupted");
  particles = std::move(loaded);
  return info;
}

}  // namespace cellsph
