/* One-way latency between two cores (ns): two threads pinned to CPUs A and B pass a
 * counter back and forth through one cache line, 200,000 round trips.
 *
 *   gcc -O2 -pthread benchmarks/core_latency.c -o /tmp/core_latency && /tmp/core_latency [A B]
 *
 * Tags a 2-thread benchmark run with where the hypervisor put the VM's two vCPUs: on a
 * 2-core AMD EPYC VM it reads 26-45 ns (one L3 cache) or 158-190 ns (two), and tribodem's
 * 2-thread settle3d runs ~20 % slower in the second state (BENCHMARKS.md, DEM engine).
 * Run it on an idle machine: a busy core makes the spinning thread wait for its turn. */
#define _GNU_SOURCE
#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#define N 200000
static _Atomic long flag __attribute__((aligned(64)));
static int cpu_a = 0, cpu_b = 1;

static void pin(int c) {
    cpu_set_t s;
    CPU_ZERO(&s);
    CPU_SET(c, &s);
    pthread_setaffinity_np(pthread_self(), sizeof s, &s);
}

static void *other(void *arg) {
    (void)arg;
    pin(cpu_b);
    for (long i = 0; i < N; i++) {
        while (atomic_load_explicit(&flag, memory_order_acquire) != 2 * i + 1) {}
        atomic_store_explicit(&flag, 2 * i + 2, memory_order_release);
    }
    return 0;
}

int main(int argc, char **argv) {
    if (argc == 3) {
        cpu_a = atoi(argv[1]);
        cpu_b = atoi(argv[2]);
    }
    pthread_t t;
    pin(cpu_a);
    pthread_create(&t, 0, other, 0);
    struct timespec a, b;
    clock_gettime(CLOCK_MONOTONIC, &a);
    for (long i = 0; i < N; i++) {
        atomic_store_explicit(&flag, 2 * i + 1, memory_order_release);
        while (atomic_load_explicit(&flag, memory_order_acquire) != 2 * i + 2) {}
    }
    clock_gettime(CLOCK_MONOTONIC, &b);
    pthread_join(t, 0);
    double ns = ((b.tv_sec - a.tv_sec) * 1e9 + (b.tv_nsec - a.tv_nsec)) / N / 2;
    printf("one-way %.1f ns (cpus %d, %d)\n", ns, cpu_a, cpu_b);
    return 0;
}
