/* test_service_config.c - grainpackd's options: defaults, environment fallbacks, flags
 * over the environment, refusals with a message, and the CORS origin list. */
#include <stdio.h>
#include <stdlib.h>

#include "check.h"
#include "config.h"

/* Loads a config from argv (NULL-terminated) with errors going to a scratch stream;
 * returns gp_config_load's status. */
static int load(gp_config *cfg, const char **args)
{
    const char *argv[16] = {"grainpackd"};
    int argc = 1;
    while (args && args[argc - 1] && argc < 15) {
        argv[argc] = args[argc - 1];
        argc++;
    }
    FILE *sink = tmpfile();
    int rc = gp_config_load(cfg, argc, (char **)argv, sink, sink);
    fclose(sink);
    return rc;
}

static void test_defaults_listen_on_loopback_with_the_database_under_data(void)
{
    gp_config cfg;
    CHECK(load(&cfg, NULL) == 0);
    CHECK_STR(cfg.host, "127.0.0.1");
    CHECK(cfg.port == 8080);
    CHECK_STR(cfg.db_path, "data/grainpack.db");
    CHECK(cfg.workers >= 1 && cfg.http_threads >= 1);
    CHECK(cfg.max_body == 1048576 && cfg.max_queued == 10000 && cfg.max_disks == 2000000);
    CHECK(cfg.cors_origins[0] == '\0');
}

static void test_environment_is_the_fallback_and_flags_win(void)
{
    setenv("GRAINPACKD_PORT", "9000", 1);
    setenv("GRAINPACKD_WORKERS", "3", 1);
    setenv("GRAINPACKD_DATA_DIR", "/var/lib/gp", 1);
    gp_config cfg;
    const char *args[] = {"--port", "9100", NULL};
    CHECK(load(&cfg, args) == 0);
    CHECK(cfg.port == 9100);
    CHECK(cfg.workers == 3);
    CHECK_STR(cfg.db_path, "/var/lib/gp/grainpack.db");
    const char *db[] = {"--db", "/tmp/x.db", NULL};
    CHECK(load(&cfg, db) == 0);
    CHECK_STR(cfg.db_path, "/tmp/x.db");
    unsetenv("GRAINPACKD_PORT");
    unsetenv("GRAINPACKD_WORKERS");
    unsetenv("GRAINPACKD_DATA_DIR");
}

static void test_bad_values_are_refused(void)
{
    gp_config cfg;
    const char *bad[][3] = {{"--port", "70000", NULL},  {"--workers", "0", NULL},
                            {"--workers", "two", NULL}, {"--max-body", "-5", NULL},
                            {"--frobnicate", "1", NULL}, {"--port", NULL, NULL}};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++)
        CHECK_MSG(load(&cfg, bad[i]) == -1, "%s %s accepted", bad[i][0], bad[i][1] ? bad[i][1] : "");
    setenv("GRAINPACKD_MAX_QUEUED", "lots", 1);
    CHECK(load(&cfg, NULL) == -1);
    unsetenv("GRAINPACKD_MAX_QUEUED");
    const char *help[] = {"--help", NULL};
    CHECK(load(&cfg, help) == 1);
}

static void test_cors_origins_match_whole_entries_only(void)
{
    gp_config cfg;
    const char *args[] = {"--cors-origins", "https://lab.example, http://localhost:3000", NULL};
    CHECK(load(&cfg, args) == 0);
    CHECK(gp_config_origin_allowed(&cfg, "https://lab.example"));
    CHECK(gp_config_origin_allowed(&cfg, "http://localhost:3000"));
    CHECK(!gp_config_origin_allowed(&cfg, "https://lab.example.evil"));
    CHECK(!gp_config_origin_allowed(&cfg, "https://lab"));
    CHECK(!gp_config_origin_allowed(&cfg, NULL));
    const char *any[] = {"--cors-origins", "*", NULL};
    CHECK(load(&cfg, any) == 0);
    CHECK(gp_config_origin_allowed(&cfg, "https://anywhere.example"));
    CHECK(load(&cfg, NULL) == 0);
    CHECK(!gp_config_origin_allowed(&cfg, "https://lab.example"));
}

int main(void)
{
    RUN(test_defaults_listen_on_loopback_with_the_database_under_data);
    RUN(test_environment_is_the_fallback_and_flags_win);
    RUN(test_bad_values_are_refused);
    RUN(test_cors_origins_match_whole_entries_only);
    return check_status();
}
