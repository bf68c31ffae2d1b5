/* What the program is specialised for. The host derives the WP_FEATURE_* set from the scene
 * (host/device/scene_features.cpp) and passes each as -D WP_FEATURE_X=0|1, so code for what a scene
 * does not use is not compiled at all; the render settings below are -D options too. Anything left
 * undefined takes its default: every feature on (the all-features build), full MIS. */
#ifndef WP_FEATURES_H
#define WP_FEATURES_H

#ifndef WP_BVH_INSTANCES
#define WP_BVH_INSTANCES 0 /* a two-level BVH (shared/bvh_layout.h): the scene's structure */
#endif
/* Shadow rays and closest-hit rays traced eight to a work-item (traverse8_packet.h): the host's
 * choice. */
#ifndef WP_SHADOW_PACKET
#define WP_SHADOW_PACKET 0
#endif
#ifndef WP_CLOSEST_PACKET
#define WP_CLOSEST_PACKET 0
#endif
/* The closest-hit packet's triangle lanes taken by mask, without a branch on whether any lies
 * inside (traverse8_packet.h): the host's choice, for scenes of few large triangles. */
#ifndef WP_PACKET_MASKED_CLOSEST
#define WP_PACKET_MASKED_CLOSEST 0
#endif
/* The fused shade kernel for eight paths per work-item (integrator/shade_packet.h): the host's
 * choice, for scenes whose BSDF is Lambert's or WP_BSDF_PLAIN's (bsdf/closure.h). */
#ifndef WP_SHADE_PACKET
#define WP_SHADE_PACKET 0
#endif
/* 1 where the host builds those packet kernels for a device other than PoCL's CPU devices
 * (--force-packets, for the Oclgrind tests; common.h, WP_LANES_FN). */
#ifndef WP_PACKETS_FORCED
#define WP_PACKETS_FORCED 0
#endif
#ifndef WP_FEATURE_PUNCTUAL_LIGHTS
#define WP_FEATURE_PUNCTUAL_LIGHTS 1 /* point, spot or directional lights */
#endif
#ifndef WP_FEATURE_SPOT_LIGHTS
#define WP_FEATURE_SPOT_LIGHTS 1 /* spot cone falloff */
#endif
#ifndef WP_FEATURE_EMISSION
#define WP_FEATURE_EMISSION 1 /* emissive triangles: emission at hits, area-light NEE */
#endif
#ifndef WP_FEATURE_ENVIRONMENT
#define WP_FEATURE_ENVIRONMENT 1 /* an environment map (else a constant background) */
#endif
#ifndef WP_ENV_BILINEAR
#define WP_ENV_BILINEAR 0 /* --env-filter bilinear: the map's lookup (lights/environment.h) */
#endif
#ifndef WP_FEATURE_VERTEX_COLORS
#define WP_FEATURE_VERTEX_COLORS 1 /* COLOR_0 multiplies the base colour */
#endif
#ifndef WP_FEATURE_TEXTURES
#define WP_FEATURE_TEXTURES 1 /* any material texture */
#endif
#ifndef WP_FEATURE_TEXTURE_LOD
#define WP_FEATURE_TEXTURE_LOD                                      \
  1 /* mip-mapped textures looked up through ray cones (ray_cone.h) \
     */
#endif
#ifndef WP_FEATURE_NORMAL_MAPS
#define WP_FEATURE_NORMAL_MAPS 1 /* tangent-space normal textures */
#endif
#ifndef WP_FEATURE_ALPHA
#define WP_FEATURE_ALPHA 1 /* alphaMode MASK or BLEND */
#endif
#ifndef WP_FEATURE_UNLIT
#define WP_FEATURE_UNLIT 1 /* KHR_materials_unlit */
#endif
#ifndef WP_FEATURE_GLOSSY
#define WP_FEATURE_GLOSSY 1 /* a specular layer (metallic or specular factor > 0, transmission) */
#endif
#ifndef WP_FEATURE_TRANSMISSION
#define WP_FEATURE_TRANSMISSION 1 /* KHR_materials_transmission */
#endif
#ifndef WP_FEATURE_VOLUME
#define WP_FEATURE_VOLUME 1 /* KHR_materials_volume: refraction and absorption */
#endif

/* The material extensions beyond metallic-roughness (kernels/bsdf/bsdf.h), each compiled in only
 * when a material of the scene uses it (host/device/scene_features.cpp). */
#ifndef WP_FEATURE_SPECULAR
#define WP_FEATURE_SPECULAR 1 /* KHR_materials_specular colour or textures */
#endif
#ifndef WP_FEATURE_CLEARCOAT
#define WP_FEATURE_CLEARCOAT 1 /* KHR_materials_clearcoat */
#endif
#ifndef WP_FEATURE_SHEEN
#define WP_FEATURE_SHEEN 1 /* KHR_materials_sheen */
#endif
#ifndef WP_FEATURE_ANISOTROPY
#define WP_FEATURE_ANISOTROPY 1 /* KHR_materials_anisotropy */
#endif
#ifndef WP_FEATURE_IRIDESCENCE
#define WP_FEATURE_IRIDESCENCE 1 /* KHR_materials_iridescence */
#endif
#ifndef WP_FEATURE_DIFFUSE_TRANSMISSION
#define WP_FEATURE_DIFFUSE_TRANSMISSION 1 /* KHR_materials_diffuse_transmission */
#endif
#ifndef WP_FEATURE_DISPERSION
#define WP_FEATURE_DISPERSION 1 /* KHR_materials_dispersion (with KHR_materials_volume) */
#endif

/* Sample pattern (rng.h): Owen-scrambled Sobol' (the light and BSDF pairs of two bounces chained
 * to one order, or padded: every group in an order of its own) or independent hashes. */
#define WP_SAMPLER_INDEPENDENT 0
#define WP_SAMPLER_SOBOL 1
#define WP_SAMPLER_SOBOL_PADDED 2
#ifndef WP_SAMPLER
#define WP_SAMPLER WP_SAMPLER_SOBOL
#endif

/* Sampling strategy for direct light (Launch.strategy, not a build option): full MIS of NEE and
 * BSDF sampling, NEE only, BSDF only. */
#define WP_STRATEGY_MIS 0
#define WP_STRATEGY_NEE 1
#define WP_STRATEGY_BSDF 2
/* MIS heuristic: 1 power (beta = 2), 0 balance. */
#ifndef WP_MIS_POWER
#define WP_MIS_POWER 1
#endif

/* The work-group size every stage kernel is launched with (the host's --local-size): the kernels
 * that append to queues do it once per work-group (queues.h, queue_push_group) with a scan in local
 * memory of this many entries, and require it (WP_GROUP_KERNEL). */
#ifndef WP_GROUP_SIZE
#define WP_GROUP_SIZE 64
#endif

/* Prefetching: 1 (the host sets it on PoCL's CPU devices) lets the stages that read path state
 * through a queue hint the cache at the slot WP_PREFETCH_AHEAD entries further along (stage.h,
 * prefetch_slot). The slots of a queue are scattered over a path state of tens of megabytes, and
 * a CPU runs a work-group's work-items one after the other, so without the hint each one starts by
 * waiting for its own cache misses. */
#ifndef WP_PREFETCH
#define WP_PREFETCH 0
#endif
#define WP_PREFETCH_AHEAD 32u

/* AOVs: 1 records each sample's albedo, normal and depth (path_state.def, shade_surface.cl)
 * and adds them to the film (shared/film.h); 0 (the default) compiles none of it. */
/* A thin-lens camera (camera.h): programs of pinhole cameras carry no lens code, so they run the
 * same arithmetic as before there was a lens (LLVM's code for the pinhole ray differed in its last
 * bits once the lens branch was beside it). */
#ifndef WP_THIN_LENS
#define WP_THIN_LENS 0
#endif

#ifndef WP_AOV
#define WP_AOV 0
#endif

#endif /* WP_FEATURES_H */
