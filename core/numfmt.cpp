// numfmt.cpp - the shortest round-trip decimal of a double, from double-conversion (the
// library behind V8's and Firefox's number printing, packaged by Debian), behind a C API.
#include <double-conversion/double-conversion.h>

#include "grainpack/out.h"

extern "C" size_t gp_fmt_double(char *buf, double x)
{
    // ECMAScript's rules (decimal notation from 1e-6 to 1e21, exponent otherwise),
    // which every JSON, CSV and XML reader parses; built here rather than shared so
    // that the library holds no global state.
    using double_conversion::DoubleToStringConverter;
    const DoubleToStringConverter converter(
        DoubleToStringConverter::EMIT_POSITIVE_EXPONENT_SIGN,
        "Infinity", "NaN", 'e', -6, 21, 6, 0);
    double_conversion::StringBuilder builder(buf, GP_FMT_DOUBLE_MAX + 1);
    converter.ToShortest(x, &builder);
    int len = builder.position();
    builder.Finalize();
    return static_cast<size_t>(len);
}
