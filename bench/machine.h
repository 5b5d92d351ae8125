/* machine.h - the line every benchmark starts with: the CPU, the cores, the build, and
 * how loaded the machine was, so that a table can be read against where it came from. */
#ifndef GRAINPACK_BENCH_MACHINE_H
#define GRAINPACK_BENCH_MACHINE_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static inline void print_machine(void)
{
    char model[256] = "unknown CPU";
    FILE *f = fopen("/proc/cpuinfo", "r");
    if (f) {
        char line[512];
        while (fgets(line, sizeof line, f)) {
            if (strncmp(line, "model name", 10) == 0) {
                char *colon = strchr(line, ':');
                if (colon) {
                    snprintf(model, sizeof model, "%s", colon + 2);
                    model[strcspn(model, "\n")] = '\0';
                }
                break;
            }
        }
        fclose(f);
    }
#ifdef __OPTIMIZE__
    const char *build = "optimised";
#else
    const char *build = "unoptimised";
#endif
    double load = 0.0;
    if (getloadavg(&load, 1) != 1)
        load = -1.0;
    printf("Machine: %s, %ld cores online; one thread; %s build; load average %.2f at the start.\n\n",
           model, sysconf(_SC_NPROCESSORS_ONLN), build, load);
}

#endif
