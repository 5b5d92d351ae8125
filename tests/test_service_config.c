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
    CHECK(cfg.max_bins == 10000 && cfg.max_job_seconds == 600.0 && cfg.max_jobs_per_key == 100);
    CHECK(cfg.max_header_bytes == 8192 && cfg.max_connections == 1024);
    CHECK(cfg.max_connections_per_ip == 128 && cfg.connection_timeout == 30);
    CHECK(cfg.key_file[0] == '\0' && cfg.insecure_open == 0);
}

static void test_limits_take_flags_and_environment(void)
{
    gp_config cfg;
    setenv("GRAINPACKD_MAX_JOB_SECONDS", "0.25", 1);
    setenv("GRAINPACKD_INSECURE_OPEN", "0", 1);
    const char *args[] = {"--max-jobs-per-key", "0", "--connection-timeout", "5",
                          "--max-connections-per-ip", "7", "--max-header-bytes", "2048", NULL};
    CHECK(load(&cfg, args) == 0);
    CHECK(cfg.max_job_seconds == 0.25 && cfg.max_jobs_per_key == 0);
    CHECK(cfg.connection_timeout == 5 && cfg.max_connections_per_ip == 7);
    CHECK(cfg.max_header_bytes == 2048 && cfg.insecure_open == 0);
    setenv("GRAINPACKD_INSECURE_OPEN", "maybe", 1);
    CHECK(load(&cfg, NULL) == -1);
    unsetenv("GRAINPACKD_INSECURE_OPEN");
    setenv("GRAINPACKD_MAX_JOB_SECONDS", "-1", 1);
    CHECK(load(&cfg, NULL) == -1);
    setenv("GRAINPACKD_MAX_JOB_SECONDS", "1e9", 1);
    CHECK(load(&cfg, NULL) == -1);
    unsetenv("GRAINPACKD_MAX_JOB_SECONDS");
    const char *small[] = {"--max-header-bytes", "100", NULL};
    CHECK(load(&cfg, small) == -1);
}

static void test_open_daemon_stays_on_loopback_unless_told(void)
{
    gp_config cfg;
    const char *loop[][3] = {{"--host", "127.0.0.1", NULL}, {"--host", "127.8.9.10", NULL},
                             {"--host", "::1", NULL}, {"--host", "::ffff:127.0.0.1", NULL}};
    for (size_t i = 0; i < sizeof loop / sizeof loop[0]; i++)
        CHECK_MSG(load(&cfg, loop[i]) == 0, "%s refused", loop[i][1]);
    const char *any[] = {"--host", "0.0.0.0", NULL};
    CHECK(load(&cfg, any) == -1);
    const char *lan[] = {"--host", "192.168.1.5", NULL};
    CHECK(load(&cfg, lan) == -1);
    const char *v6[] = {"--host", "::", NULL};
    CHECK(load(&cfg, v6) == -1);
    const char *told[] = {"--host", "0.0.0.0", "--insecure-open", NULL};
    CHECK(load(&cfg, told) == 0 && cfg.insecure_open == 1);
    const char *keys[] = {"--host", "0.0.0.0", "--key-file", "/etc/grainpack/keys", NULL};
    CHECK(load(&cfg, keys) == 0);
    setenv("GRAINPACKD_INSECURE_OPEN", "1", 1);
    CHECK(load(&cfg, any) == 0);
    unsetenv("GRAINPACKD_INSECURE_OPEN");
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
    RUN(test_limits_take_flags_and_environment);
    RUN(test_open_daemon_stays_on_loopback_unless_told);
    RUN(test_cors_origins_match_whole_entries_only);
    return check_status();
}
