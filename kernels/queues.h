/* Queues of path slots.
 *
 * A queue is an array of path-slot indices plus a counter, both in device memory: queue q occupies
 * queues[q * capacity ...] and its length is counters[q]. The invariant: at any kernel boundary,
 * counters[q] <= capacity and entries [0, counters[q]) are distinct live slots. Producers append
 * with an atomic increment (order is therefore arbitrary, and nothing may depend on it: every
 * result is a function of the slot's own state and its stateless random numbers). Consumers are
 * launched over an upper bound of the length and return past counters[q], so the host never has to
 * read a counter back to launch the next stage. Every kernel moves a slot to at most one next
 * queue, or ends the path there.
 */
#ifndef WP_QUEUES_H
#define WP_QUEUES_H

#include "common.h"

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

static inline void queue_push(Queues qs, uint q, uint slot) {
  const uint at = atomic_inc(&qs.counters[q]);
  qs.slots[q * qs.capacity + at] = slot;
}

/* Counts a NaN or infinite value that a stage drops (it must never happen; the renderer reports
 * the count and the tests require 0). Every place that drops such a value counts it, so that no
 * failure is silent. */
static inline void count_nonfinite(Queues qs) {
  atomic_inc(&qs.counters[WP_COUNTER_NONFINITE]);
}

#endif /* WP_QUEUES_H */
