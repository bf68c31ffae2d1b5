/* The film in fixed point: the layout shared by the accumulate kernel, the host's Film
 * (host/film/film.h) and the .wpfilm file, which stores the device buffer word for word.
 *
 * A sample's radiance v (per channel; finite, NaN/Inf are dropped and counted before) becomes the
 * integer a = round(v * 2^32), ties to even, saturated to [0, 2^64 - 1] (integrator/accumulate.h,
 * film_fixed): 32 fraction bits, so values below 2^-33 round to 0 and values from 2^32 on
 * saturate. Per pixel and channel the film keeps two 128-bit unsigned sums, S = sum(a) and
 * Q = sum(floor(a^2 / 2^32)), so mean = S / 2^32 / n and sum(v^2) = Q / 2^32. Integer addition
 * is associative and commutative: films of disjoint sample ranges add up, in any order, to exactly
 * the film of one render.
 *
 * Ranges: a < 2^64 and a^2 / 2^32 < 2^96, so after n <= WP_FILM_MAX_SAMPLES = 2^20 samples
 * S < 2^84 and Q < 2^116: no sum can overflow 128 bits, whatever the values (saturated ones
 * included); Q would first overflow after 2^32 samples.
 *
 * Layout: WP_FILM_WORDS_PER_PIXEL 64-bit words per pixel (WP_FILM_WORDS(aov) with AOVs, below),
 * pixels row by row from the top; each 128-bit value is two words, the low word first: S of R, G, B
 * (WP_FILM_SUM(c)), then Q of R, G, B (WP_FILM_SQUARES(c)). 96 bytes per pixel.
 */
#ifndef WP_SHARED_FILM_H
#define WP_SHARED_FILM_H

#define WP_FILM_FRACTION_BITS 32
#define WP_FILM_MAX_SAMPLES (1u << 20) /* sample indices lie in [0, WP_FILM_MAX_SAMPLES) */
#define WP_FILM_WORDS_PER_PIXEL 12u
#define WP_FILM_SUM(c) (2u * (c))          /* word offset of S (low word) of channel c */
#define WP_FILM_SQUARES(c) (6u + 2u * (c)) /* word offset of Q (low word) of channel c */

/* With AOVs (WP_AOV, RenderSettings::aov) 14 more words per pixel follow the 12: 128-bit sums,
 * one value per sample, of round(v * 2^32) saturated as above, for the albedo's R, G, B
 * (WP_FILM_ALBEDO(c)), the normal's X + 1, Y + 1, Z + 1 (WP_FILM_NORMAL(c); the 1 keeps them
 * non-negative) and the depth in metres (WP_FILM_DEPTH). 208 bytes per pixel. */
#define WP_FILM_AOV_WORDS 14u
#define WP_FILM_ALBEDO(c) (12u + 2u * (c))
#define WP_FILM_NORMAL(c) (18u + 2u * (c))
#define WP_FILM_DEPTH 24u
#define WP_FILM_WORDS(aov) \
  ((aov) ? WP_FILM_WORDS_PER_PIXEL + WP_FILM_AOV_WORDS : WP_FILM_WORDS_PER_PIXEL)

#endif /* WP_SHARED_FILM_H */
