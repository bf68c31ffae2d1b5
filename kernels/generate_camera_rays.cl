/* Stage: camera-ray generation (integrator/generate_camera_rays.h).
 * From: nothing; a new sample pass over the wave's pixels, launched over launch.path_count.
 * To:   every slot of the wave a fresh path, all of them in queue_out. */
#include "integrator/generate_camera_rays.h"

__kernel void generate_camera_rays(WP_STAGE_PARAMS) {
  WP_STAGE_BIND;
#if WP_SHADE_PACKET /* eight slots per work-item, as shade takes them */
  const uint first = get_global_id(0) * 8u;
  if (first >= launch.path_count) return;
  start_paths8(&scene_desc.camera, paths, launch, first);
  for (uint slot = first; slot < min(first + 8u, launch.path_count); ++slot)
    queues.slots[launch.queue_out * queues.capacity + slot] = slot;
  if (first == 0) queues.counters[launch.queue_out] = launch.path_count;
#else
  const uint slot = get_global_id(0);
  if (slot >= launch.path_count) return;
  start_path(&scene_desc.camera, paths, launch, slot);
  queues.slots[launch.queue_out * queues.capacity + slot] = slot;
  if (slot == 0) queues.counters[launch.queue_out] = launch.path_count;
#endif
}
