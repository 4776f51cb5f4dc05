#pragma once
// Particles to the ranks that own them (issue 49 item 2, docs/distributed.md): after the curve's cuts
// (curve_split.hpp) give each particle its rank, every field of the particles that leave goes to their new
// rank in one all-to-all exchange, and each rank sorts what it holds by the particles' ids: the order a
// single process would keep them in, so a rank's sums run in the single-process order whatever the rank
// count. Generic over a struct of arrays with the particles' field list (solver/particles.hpp:
// for_each_field, resize, id), every field one trivially copyable element per particle.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <numeric>
#include <span>
#include <string_view>
#include <type_traits>
#include <vector>

#include "cellsph/core/error.hpp"
#include "cellsph/distributed/communicator.hpp"

namespace cellsph::distributed {

namespace migrate_detail {

template <class T>
void append(std::vector<std::byte>& out, const T& value) {
  const auto* b = reinterpret_cast<const std::byte*>(&value);
  out.insert(out.end(), b, b + sizeof(T));
}

}  // namespace migrate_detail

// Appends to a message the particles `which` of p: their count, then field by field (the field list's
// order) their elements.
template <class Soa>
void pack(const Soa& p, std::span<const std::size_t> which, std::vector<std::byte>& out) {
  migrate_detail::append(out, static_cast<std::uint64_t>(which.size()));
  const std::size_t n = p.size();
  p.for_each_field([&](std::string_view name, const auto& field) {
    using T = typename std::decay_t<decltype(field)>::value_type;
    static_assert(std::is_trivially_copyable_v<T>, "a field sent to another rank must be trivially copyable");
    CELLSPH_CHECK(field.size() == n, "pack: field " << name << " has " << field.size() << " of " << n);
    for (const std::size_t i : which) migrate_detail::append(out, field[i]);
  });
}

// Appends to p the particles of the messages in `in` (from[r] bytes from rank r, each a pack()), source
// rank by source rank; returns how many came from each.
template <class Soa>
std::vector<std::uint64_t> unpack_append(Soa& p, const std::vector<std::byte>& in,
                                         const std::vector<std::size_t>& from) {
  std::vector<std::uint64_t> count(from.size());
  std::size_t first = p.size(), total = p.size(), at = 0;
  for (std::size_t r = 0; r < from.size(); ++r) {
    std::memcpy(&count[r], in.data() + at, sizeof(std::uint64_t));
    total += count[r];
    at += from[r];
  }
  p.resize(total);
  at = 0;
  for (std::size_t r = 0; r < from.size(); ++r) {
    std::size_t pos = at + sizeof(std::uint64_t);
    p.for_each_field([&](std::string_view, auto& field) {
      using T = typename std::decay_t<decltype(field)>::value_type;
      for (std::size_t k = 0; k < count[r]; ++k, pos += sizeof(T))
        std::memcpy(&field[first + k], in.data() + pos, sizeof(T));
    });
    CELLSPH_CHECK(pos == at + from[r], "unpack: a message from rank " << r << " of " << from[r] << " bytes");
    at += from[r];
    first += count[r];
  }
  return count;
}

// Sorts every field of p by id; returns the permutation (element k is the old element order[k]).
template <class Soa>
std::vector<std::size_t> sort_by_id(Soa& p) {
  std::vector<std::size_t> order(p.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return p.id[a] < p.id[b]; });
  p.for_each_field([&](std::string_view, auto& field) {
    auto old = field;
    for (std::size_t k = 0; k < order.size(); ++k) field[k] = old[order[k]];
  });
  return order;
}

// Sends particle i of this rank to rank dest[i] (one entry per particle, each in [0, ranks)); afterwards
// this rank holds every particle sent to it by any rank (itself included), in ascending id order.
template <class Soa>
void migrate(Soa& p, std::span<const int> dest, const Communicator& comm) {
  const std::size_t n = p.size();
  const auto ranks = static_cast<std::size_t>(comm.size());
  CELLSPH_CHECK(dest.size() == n, "migrate: " << dest.size() << " destinations for " << n << " particles");
  std::vector<std::vector<std::size_t>> leaving(ranks);
  for (std::size_t i = 0; i < n; ++i) {
    CELLSPH_CHECK(dest[i] >= 0 && static_cast<std::size_t>(dest[i]) < ranks,
                  "migrate: particle " << i << " to rank " << dest[i] << " of " << ranks);
    leaving[static_cast<std::size_t>(dest[i])].push_back(i);
  }
  std::vector<std::vector<std::byte>> to_rank(ranks);
  for (std::size_t r = 0; r < ranks; ++r) pack(p, std::span<const std::size_t>(leaving[r]), to_rank[r]);
  std::vector<std::size_t> from;
  const std::vector<std::byte> in = comm.all_to_all(to_rank, from);
  p.resize(0);
  unpack_append(p, in, from);
  sort_by_id(p);
}

}  // namespace cellsph::distributed
