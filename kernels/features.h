/* Scene features the program is specialised for. The host derives them from the scene
 * (host/scene_features.cpp) and passes each as -D WP_FEATURE_X=0|1, so code for what a scene does
 * not use is not compiled at all. A feature left undefined is on: the all-features build. */
#ifndef WP_FEATURES_H
#define WP_FEATURES_H

#ifndef WP_FEATURE_PUNCTUAL_LIGHTS
#define WP_FEATURE_PUNCTUAL_LIGHTS 1 /* point, spot or directional lights (NEE) */
#endif
#ifndef WP_FEATURE_SPOT_LIGHTS
#define WP_FEATURE_SPOT_LIGHTS 1 /* spot cone falloff */
#endif
#ifndef WP_FEATURE_EMISSION
#define WP_FEATURE_EMISSION 1 /* emissive triangles */
#endif
#ifndef WP_FEATURE_VERTEX_COLORS
#define WP_FEATURE_VERTEX_COLORS 1 /* COLOR_0 multiplies the base colour */
#endif

#endif /* WP_FEATURES_H */
