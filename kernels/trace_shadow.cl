/* Stage: shadow rays (integrator/trace_shadow.h).
 * From: WP_QUEUE_SHADOW, its entries from launch.shadow_first on (with WP_SHADOW_PACKET and
 *       launch.shadow_packet > 1 a packet of WP_PACKET rays per work-item: traverse8_packet.h);
 *       launched over its exact length, or over an estimate of it and then the rest
 *       (Wavefront::run_bounce). Entries past the queue's length are skipped.
 * To:   the radiance of every path whose shadow ray reaches its light; the queue ends here. */
#include "integrator/trace_shadow.h"

__kernel void trace_shadow(WP_STAGE_PARAMS) {
  WP_STAGE_BIND;
#if WP_SHADOW_PACKET
  if (launch.shadow_packet > 1u) {
    trace_shadow_packet(&scene, paths, queues,
                        launch.shadow_first + (uint)get_global_id(0) * WP_PACKET);
    return;
  }
#endif
  const uint entry = launch.shadow_first + (uint)get_global_id(0);
  uint slot, ahead;
  if (prefetch_slot(queues, WP_QUEUE_SHADOW, entry, &ahead)) trace_shadow_prefetch(paths, ahead);
  if (queue_get(queues, WP_QUEUE_SHADOW, entry, &slot))
    trace_shadow_path(&scene, paths, launch, slot);
}
