/* api.h - GP_API marks the functions libgrainpack exports. The library is compiled with
 * hidden visibility by default, so its shared object exports these and nothing else (no
 * internal helper, no CGAL instantiation), and the installed static archive keeps only
 * them global (dist/localize_archive.cmake). GP_PRINTF(f, a) marks a printf-like function
 * (format string argument f, first variadic argument a) for the compiler's checks. */
#ifndef GRAINPACK_API_H
#define GRAINPACK_API_H

#if defined(__GNUC__) && __GNUC__ >= 4
#define GP_API __attribute__((visibility("default")))
#define GP_PRINTF(f, a) __attribute__((format(printf, f, a)))
#else
#define GP_API
#define GP_PRINTF(f, a)
#endif

#endif
