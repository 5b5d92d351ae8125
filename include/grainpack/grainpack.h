/* grainpack.h - the whole public API of libgrainpack in one include, and the rules every
 * function of it keeps. A program needs nothing else: `#include <grainpack/grainpack.h>`,
 * link with grainpack::grainpack (CMake) or `pkg-config --libs grainpack`.
 *
 * What the library promises:
 *
 * - Reentrant, no global state. Every function works only on what its arguments point
 *   to: the library keeps no mutable global or static variable (its only writable
 *   globals are CGAL's and Boost's function-local constants, initialised once under the
 *   C++ runtime's thread-safe initialisation and read-only after). Randomness comes from
 *   the gp_rng the caller passes (a spec's seed), so a job's output depends on its
 *   inputs alone and two jobs run side by side on two threads without any lock.
 *
 * - Sharing between threads. An object may be read by any number of threads at once,
 *   through the const pointers the functions take, while no thread changes it: a parsed
 *   gp_spec (its gp_distribution prepared), a gp_result and everything in it (gp_packing,
 *   gp_cells, the statistics), a gp_rt that is not being updated (gp_rt_ring, gp_quality
 *   and gp_laguerre only read it). An object a function takes by non-const pointer is
 *   that call's alone for its duration: a gp_rng (every draw advances it), a gp_out, a
 *   gp_writer (and the gp_grain_source it reads), a gp_error, a gp_rt under gp_balance
 *   or gp_rt_update_moved, any result being filled.
 *   gp_progress: report() runs on the thread that runs the stage; *cancel is atomic and
 *   may be raised from any thread.
 *
 * - Errors. A fallible function returns 0 or a negative GP_E... code (error.h) and puts
 *   the message, with the JSON pointer of the field at fault, in a gp_error the caller
 *   owns; on failure its outputs are left zeroed (each function's comment says what
 *   stays valid). Out of memory is GP_ENOMEM, never an abort. The library writes nothing
 *   to stdout or stderr, installs no signal handler and never exits the process; no
 *   C++ exception crosses its API.
 *
 * - Ownership. Each function's comment says what the caller borrows, what it owns and
 *   which gp_..._free releases it; a gp_..._free of a struct zeroes it and accepts a
 *   zeroed one (freeing twice is harmless), gp_rt_free and gp_writer_free accept NULL.
 *
 * - Numbers in text. The writers (io.h) and gp_out's number formats (out.h) write the
 *   grains' numbers without the C library, whatever the locale; the SVG picture's
 *   captions and gp_out_printf use printf: keep LC_NUMERIC at "C" (the default of every
 *   program that does not call setlocale) while they run, or decimal commas appear there.
 *
 * - ABI. Only the functions marked GP_API are exported; the headers show no third-party
 *   type (jansson, CGAL stay inside). Version 0.x: a minor release may change the API;
 *   the SONAME follows the major version. GP_VERSION (the headers) against gp_version()
 *   (the library linked) tells a program built against one and run with another. */
#ifndef GRAINPACK_GRAINPACK_H
#define GRAINPACK_GRAINPACK_H

#include "grainpack/api.h"
#include "grainpack/balance.h"
#include "grainpack/disk.h"
#include "grainpack/distribution.h"
#include "grainpack/domain.h"
#include "grainpack/error.h"
#include "grainpack/io.h"
#include "grainpack/io3d.h"
#include "grainpack/io_mesh.h"
#include "grainpack/joint.h"
#include "grainpack/laguerre.h"
#include "grainpack/mesh.h"
#include "grainpack/out.h"
#include "grainpack/pack.h"
#include "grainpack/pack3d.h"
#include "grainpack/geometry3d.h"
#include "grainpack/pipeline.h"
#include "grainpack/pipeline3d.h"
#include "grainpack/progress.h"
#include "grainpack/rng.h"
#include "grainpack/spec.h"
#include "grainpack/spec3d.h"
#include "grainpack/stats.h"
#include "grainpack/triangulation.h"
#include "grainpack/version.h"

#endif
