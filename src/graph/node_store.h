// Internal to the shortest-path engine (not part of the graph module's API): the per-node
// record of grid searches and its storage. See docs/notes/engine.md for the memory layout.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>

#include "graph/shortest_path.h"

namespace vs::engine {

constexpr uint8_t kInterior = 0x20;
constexpr uint8_t kSettled = ShortestPathSearch::kSettledBit;
constexpr uint8_t kDirMask = ShortestPathSearch::kDirectionMask;
constexpr double kInf = std::numeric_limits<double>::infinity();

// The state byte of a grid node record (bits 0-4 back direction, 5 interior, 6 settled). Not a
// plain uint8_t: a store through an unsigned char lvalue may alias any object, so the compiler
// reloaded the queue's and the model's fields after every state store in the hot loops (the
// two-thread loop ran ~1.5x slower per node for that alone). An enum has its own alias set.
enum class StateByte : uint8_t {};
struct StateCell {
  StateByte b;
  operator uint8_t() const { return uint8_t(b); }
  StateCell& operator=(uint8_t v) {
    b = StateByte(v);
    return *this;
  }
  StateCell& operator&=(uint8_t v) { return *this = uint8_t(uint8_t(b) & v); }
  StateCell& operator|=(uint8_t v) { return *this = uint8_t(uint8_t(b) | v); }
};
static_assert(sizeof(StateCell) == 1);

// Per-node record of grid searches: T, the node's cost, state and sign share one 16-byte
// record, so relaxing a neighbour touches one cache line instead of three arrays.
struct NodeRec {
  double t;
  float c;
  StateCell s;
  uint8_t sign;
  uint16_t pad;
};
static_assert(sizeof(NodeRec) == 16);
// Record storage: anonymous mmap with transparent huge pages requested (madvise): a 2-D
// neighbourhood spans 3 rows, and even a bricked 3-D one (record_layout.h) 1-8 bricks of 8 KiB,
// so with 4 KiB pages large volumes would miss the TLB on most relaxations.
// Falls back to operator new where mmap fails. Not initialised (chunks are filled lazily,
// GridModel::ensure).
struct RecordStore {
  NodeRec* p = nullptr;
  size_t bytes = 0;
  bool mapped = false;
  RecordStore() = default;
  RecordStore(const RecordStore&) = delete;
  RecordStore& operator=(const RecordStore&) = delete;
  ~RecordStore() { release(); }
  void release();
  void allocate(size_t n);
  NodeRec* get() const { return p; }
  explicit operator bool() const { return p != nullptr; }
};

}  // namespace vs::engine
