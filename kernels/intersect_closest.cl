/* Stage: closest-hit intersection (integrator/intersect_closest.h).
 * From: queue_in, the rays to trace (with WP_CLOSEST_PACKET a packet of WP_PACKET rays per
 *       work-item, launched over the queue's length divided by WP_PACKET: traverse8_packet.h).
 * To:   each slot's hit record; no queue (shade or shade_surface reads queue_in next). */
#include "integrator/intersect_closest.h"

__kernel void intersect_closest(WP_STAGE_PARAMS) {
  WP_STAGE_BIND;
#if WP_CLOSEST_PACKET
  if (launch.packet > 1u) {
    intersect_packet(&scene, paths, queues, launch.queue_in, get_global_id(0) * WP_PACKET);
    return;
  }
#endif
  uint slot, ahead;
  if (prefetch_slot(queues, launch.queue_in, get_global_id(0), &ahead))
    intersect_prefetch(paths, ahead);
  if (queue_get(queues, launch.queue_in, get_global_id(0), &slot))
    intersect_path(&scene, paths, launch, slot);
}
