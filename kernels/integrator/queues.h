/* Queues of path slots.
 *
 * A queue is an array of path-slot indices plus a counter, both in device memory: queue q occupies
 * queues[q * capacity ...] and its length is counters[q]. The invariant: at any kernel boundary,
 * counters[q] <= capacity and entries [0, counters[q]) are distinct live slots. Producers append
 * with an atomic add per work-group (order is therefore arbitrary, and nothing may depend on it:
 * every result is a function of the slot's own state and its stateless random numbers). Consumers
 * are launched over an upper bound of the length and return past counters[q], so the host reads the
 * counters back only once per bounce (host/render/wavefront.cpp, run_bounce: before trace_shadow,
 * which it launches over the shadow queue's exact length). Every kernel moves a slot to at most one
 * next queue, or ends the path there.
 */
#ifndef WP_QUEUES_H
#define WP_QUEUES_H

#include "util/common.h"

typedef struct Queues {
  __global uint* slots;    /* WP_QUEUE_COUNT arrays of `capacity` entries */
  __global uint* counters; /* WP_COUNTER_COUNT counters */
  uint capacity;
} Queues;

static inline Queues queues_bind(__global uint* slots, __global uint* counters, uint capacity) {
  Queues q = {slots, counters, capacity};
  return q;
}

/* The slot at position `index` of queue `q`, or false when index is past its length. */
static inline bool queue_get(Queues qs, uint q, uint index, uint* slot) {
  if (index >= qs.counters[q]) return false;
  *slot = qs.slots[q * qs.capacity + index];
  return true;
}

/* The slots of entries [first, first + count) of queue q that exist (a packet of rays,
 * traverse8_packet.h); returns how many. */
static inline int queue_get_run(Queues qs, uint q, uint first, int count, uint* slots) {
  int n = 0;
  while (n < count && queue_get(qs, q, first + (uint)n, &slots[n])) ++n;
  return n;
}

/* queue_push_group2 (below) for a work-item with several slots: slot i goes to queue qa where
 * bit i of push_a is set and to queue qb where bit i of push_b is set (shade_packet.h), each
 * queue's entries in slot order within the work-item. A group pushes at most WP_GROUP_SIZE * 32
 * slots to a queue, whose ranks fit in 16 bits. */
static inline void queue_push_group2_lanes(Queues qs, uint qa, uint push_a, uint qb, uint push_b,
                                           const uint* slots, __local uint* scan) {
  const uint lid = get_local_id(0);
  scan[lid] = popcount(push_a) | (popcount(push_b) << 16);
  barrier(CLK_LOCAL_MEM_FENCE);
  if (lid == 0u) { /* serial, by one work-item: a CPU runs the group as one loop anyway */
    uint total = 0u;
    for (uint i = 0u; i < WP_GROUP_SIZE; ++i) {
      const uint count = scan[i];
      scan[i] = total;
      total += count;
    }
    const uint ta = total & 0xffffu, tb = total >> 16;
    scan[WP_GROUP_SIZE] = ta ? atomic_add(&qs.counters[qa], ta) : 0u;
    scan[WP_GROUP_SIZE + 1u] = tb ? atomic_add(&qs.counters[qb], tb) : 0u;
  }
  barrier(CLK_LOCAL_MEM_FENCE);
  const uint rank = scan[lid];
  uint a = qa * qs.capacity + scan[WP_GROUP_SIZE] + (rank & 0xffffu);
  uint b = qb * qs.capacity + scan[WP_GROUP_SIZE + 1u] + (rank >> 16);
  /* One step per entry, the set bits lowest first: a test per slot and queue mispredicts where
   * paths end at random (6% of the packet shade at 1280 x 720, docs/performance.md). */
  for (uint m = push_a; m != 0u; m &= m - 1u) qs.slots[a++] = slots[lowest_bit((int)m)];
  for (uint m = push_b; m != 0u; m &= m - 1u) qs.slots[b++] = slots[lowest_bit((int)m)];
}

/* Two queue_push_group calls (below) in one: slot goes to queue qa where push_a holds and to queue
 * qb where push_b holds, with one scan of both flags packed in a word (a group's ranks fit in 16
 * bits: WP_GROUP_SIZE <= 1024), so half the barriers and scans of two calls. Each queue's entries
 * come out in the order two calls would give them. */
static inline void queue_push_group2(Queues qs, uint qa, bool push_a, uint qb, bool push_b,
                                     uint slot, __local uint* scan) {
  queue_push_group2_lanes(qs, qa, push_a ? 1u : 0u, qb, push_b ? 1u : 0u, &slot, scan);
}

/* Appends `slot` to queue `q` where `push` holds, for the whole work-group at once: a scan of the
 * group's flags in local memory, one atomic add on the queue's counter per group, and each pushing
 * work-item writes its entry at the group's base plus its rank. One atomic per work-item instead
 * cost half the time of shade_surface and roulette_compact on PoCL (a locked add on a counter the
 * other cores share, which also waits for the work-item's earlier stores to drain).
 *
 * It holds barriers: every work-item of the group must call it, in the same order as the others,
 * none having returned before. `scan` is the kernel's WP_GROUP_SCRATCH (WP_GROUP_SIZE + 2 words).
 * It is queue_push_group2 with one queue.
 * The rank is the work-item's order in its group, so a queue's order still depends on which group
 * reached the counter first (nothing may depend on it; see the top of this file). */
static inline void queue_push_group(Queues qs, uint q, bool push, uint slot, __local uint* scan) {
  queue_push_group2(qs, q, push, q, false, slot, scan);
}

/* A stage kernel that pushes to queues: launched with exactly WP_GROUP_SIZE work-items per group,
 * which its local scan (WP_GROUP_SCRATCH) is sized for. */
#define WP_GROUP_KERNEL __kernel __attribute__((reqd_work_group_size(WP_GROUP_SIZE, 1, 1)))
/* The local memory of queue_push_group, declared at the top of such a kernel. */
#define WP_GROUP_SCRATCH(name) __local uint name[WP_GROUP_SIZE + 2]

/* Counts a NaN or infinite value that a stage drops (it must never happen; the renderer reports
 * the count and the tests require 0). Every place that drops such a value counts it, so that no
 * failure is silent. */
static inline void count_nonfinite(Queues qs) {
  atomic_inc(&qs.counters[WP_COUNTER_NONFINITE]);
}

#endif /* WP_QUEUES_H */
