/* Stage: camera-ray generation (integrator/generate_camera_rays.h).
 * From: nothing; a new sample pass over the wave's pixels, launched over launch.path_count.
 * To:   every slot of the wave a fresh path, all of them in queue_out. */
#include "integrator/generate_camera_rays.h"

__kernel void generate_camera_rays(WP_STAGE_PARAMS) {
  WP_STAGE_BIND;
  const uint slot = get_global_id(0);
  if (slot >= launch.path_count) return;
  start_path(&scene_desc.camera, paths, launch, slot);
  queues.slots[launch.queue_out * queues.capacity + slot] = slot;
  if (slot == 0) queues.counters[launch.queue_out] = launch.path_count;
}
