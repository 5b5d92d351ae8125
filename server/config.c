/* config.c - parsing the daemon's flags and environment variables. */
#include "config.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define DEFAULT_MAX_BODY ((size_t)1 << 20)
#define DEFAULT_MAX_QUEUED ((size_t)10000)
/* A job this size packs in a few seconds and its result (32 bytes a disk) stays
 * under 64 MB in the database; --max-disks raises it. */
#define DEFAULT_MAX_DISKS ((size_t)2000000)
#define DEFAULT_MAX_WAIT 60

typedef enum opt_kind { OPT_TEXT, OPT_SIZE, OPT_INT } opt_kind;

typedef struct option {
    const char *flag, *env, *help;
    opt_kind kind;
    size_t offset, size; /* where in gp_config, and the field's size for OPT_TEXT */
    size_t min, max;     /* OPT_SIZE and OPT_INT range */
} option;

#define TEXT(field) OPT_TEXT, offsetof(gp_config, field), sizeof(((gp_config *)0)->field), 0, 0
#define SIZE(field, lo, hi) OPT_SIZE, offsetof(gp_config, field), 0, lo, hi
#define INT(field, lo, hi) OPT_INT, offsetof(gp_config, field), 0, lo, hi

static const option options[] = {
    {"--host", "GRAINPACKD_HOST", "address to listen on (default 127.0.0.1)", TEXT(host)},
    {"--port", "GRAINPACKD_PORT", "port (default 8080; 0 picks a free one)", INT(port, 0, 65535)},
    {"--data-dir", "GRAINPACKD_DATA_DIR", "directory of the database (default ./data)",
     TEXT(data_dir)},
    {"--db", "GRAINPACKD_DB", "database file (default DATA_DIR/grainpack.db)", TEXT(db_path)},
    {"--workers", "GRAINPACKD_WORKERS", "worker threads running jobs (default: cores)",
     INT(workers, 1, 256)},
    {"--http-threads", "GRAINPACKD_HTTP_THREADS", "HTTP threads (default: cores)",
     INT(http_threads, 1, 256)},
    {"--max-body", "GRAINPACKD_MAX_BODY", "largest request body in bytes (default 1048576)",
     SIZE(max_body, 64, (size_t)1 << 30)},
    {"--max-queued", "GRAINPACKD_MAX_QUEUED", "jobs waiting before 503 (default 10000)",
     SIZE(max_queued, 1, (size_t)1 << 30)},
    {"--max-disks", "GRAINPACKD_MAX_DISKS", "largest job in expected disks (default 2000000)",
     SIZE(max_disks, 1, (size_t)1 << 40)},
    {"--max-wait", "GRAINPACKD_MAX_WAIT", "longest ?wait= of GET /jobs/{id} in seconds (default 60)",
     INT(max_wait, 0, 3600)},
    {"--cors-origins", "GRAINPACKD_CORS_ORIGINS",
     "browser origins allowed to call the API: comma-separated, or * (default none)",
     TEXT(cors_origins)},
    {"--ready-file", NULL, "file to write the port to once listening", TEXT(ready_file)},
};
#define NOPTIONS (sizeof options / sizeof options[0])

static void usage(FILE *out)
{
    fputs("usage: grainpackd [OPTION VALUE]...\n"
          "The grainpack job service: OGC API - Processes over HTTP, jobs in sqlite.\n\n",
          out);
    for (size_t i = 0; i < NOPTIONS; i++)
        fprintf(out, "  %-16s %s%s%s\n", options[i].flag, options[i].help,
                options[i].env ? "; env " : "", options[i].env ? options[i].env : "");
    fputs("  --help, --version\n\nSIGTERM or SIGINT stops it cleanly: running jobs are queued "
          "again.\n",
          out);
}

/* Stores `value` into the field of `opt`; -1 with a message when it does not fit. */
static int set_option(gp_config *cfg, const option *opt, const char *value, const char *source,
                      FILE *err)
{
    char *field = (char *)cfg + opt->offset;
    if (opt->kind == OPT_TEXT) {
        if (strlen(value) >= opt->size) {
            fprintf(err, "grainpackd: %s: value too long (at most %zu characters)\n", source,
                    opt->size - 1);
            return -1;
        }
        memcpy(field, value, strlen(value) + 1);
        return 0;
    }
    char *end;
    errno = 0;
    unsigned long long v = strtoull(value, &end, 10);
    size_t lo = opt->min, hi = opt->max;
    if (errno || end == value || *end || value[0] == '-' || v < lo || v > hi) {
        fprintf(err, "grainpackd: %s: expected an integer from %zu to %zu, got '%s'\n", source, lo,
                hi, value);
        return -1;
    }
    if (opt->kind == OPT_INT)
        *(int *)(void *)field = (int)v;
    else
        *(size_t *)(void *)field = (size_t)v;
    return 0;
}

int gp_config_load(gp_config *cfg, int argc, char **argv, FILE *out, FILE *err)
{
    memset(cfg, 0, sizeof *cfg);
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    snprintf(cfg->host, sizeof cfg->host, "127.0.0.1");
    cfg->port = 8080;
    snprintf(cfg->data_dir, sizeof cfg->data_dir, "data");
    cfg->workers = cfg->http_threads = cores > 0 ? (int)cores : 1;
    cfg->max_body = DEFAULT_MAX_BODY;
    cfg->max_queued = DEFAULT_MAX_QUEUED;
    cfg->max_disks = DEFAULT_MAX_DISKS;
    cfg->max_wait = DEFAULT_MAX_WAIT;
    for (size_t i = 0; i < NOPTIONS; i++) {
        const char *value = options[i].env ? getenv(options[i].env) : NULL;
        if (value && *value && set_option(cfg, &options[i], value, options[i].env, err))
            return -1;
    }
    for (int a = 1; a < argc; a++) {
        if (strcmp(argv[a], "--help") == 0 || strcmp(argv[a], "-h") == 0) {
            usage(out);
            return 1;
        }
        if (strcmp(argv[a], "--version") == 0) {
            fprintf(out, "grainpackd %s\n", GP_VERSION);
            return 1;
        }
        const option *opt = NULL;
        for (size_t i = 0; i < NOPTIONS && !opt; i++)
            if (strcmp(argv[a], options[i].flag) == 0)
                opt = &options[i];
        if (!opt) {
            fprintf(err, "grainpackd: unknown option '%s'\n", argv[a]);
            usage(err);
            return -1;
        }
        if (a + 1 >= argc) {
            fprintf(err, "grainpackd: %s needs a value\n", argv[a]);
            return -1;
        }
        if (set_option(cfg, opt, argv[a + 1], opt->flag, err))
            return -1;
        a++;
    }
    if (!cfg->db_path[0]) {
        int n = snprintf(cfg->db_path, sizeof cfg->db_path, "%s/grainpack.db", cfg->data_dir);
        if (n < 0 || (size_t)n >= sizeof cfg->db_path) {
            fprintf(err, "grainpackd: data directory path too long\n");
            return -1;
        }
    }
    return 0;
}

int gp_config_origin_allowed(const gp_config *cfg, const char *origin)
{
    if (!origin || !cfg->cors_origins[0])
        return 0;
    if (strcmp(cfg->cors_origins, "*") == 0)
        return 1;
    size_t n = strlen(origin);
    for (const char *p = cfg->cors_origins; *p;) {
        while (*p == ',' || *p == ' ')
            p++;
        const char *end = p;
        while (*end && *end != ',' && *end != ' ')
            end++;
        if ((size_t)(end - p) == n && n && strncmp(p, origin, n) == 0)
            return 1;
        p = end;
    }
    return 0;
}
