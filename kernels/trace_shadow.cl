/* Stage: shadow rays (integrator/trace_shadow.h).
 * From: WP_QUEUE_SHADOW, launched over its exact length (with WP_SHADOW_PACKET and
 *       launch.shadow_packet > 1 over that length divided by WP_PACKET, a packet of rays per
 *       work-item: traverse8_packet.h).
 * To:   the radiance of every path whose shadow ray reaches its light; the queue ends here. */
#include "integrator/trace_shadow.h"

__kernel void trace_shadow(WP_STAGE_PARAMS) {
  WP_STAGE_BIND;
#if WP_SHADOW_PACKET
  if (launch.shadow_packet > 1u) {
    trace_shadow_packet(&scene, paths, queues, get_global_id(0) * WP_PACKET);
    return;
  }
#endif
  uint slot, ahead;
  if (prefetch_slot(queues, WP_QUEUE_SHADOW, get_global_id(0), &ahead))
    trace_shadow_prefetch(paths, ahead);
  if (queue_get(queues, WP_QUEUE_SHADOW, get_global_id(0), &slot))
    trace_shadow_path(&scene, paths, launch, slot);
}
