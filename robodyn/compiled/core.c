/* robodyn.compiled core: the C every compiled module shares, written once (see build.py,
 * which places this text before a module's kernels):
 *
 *   RD_LDL_DEFINE(Q, P, T): the tree LDLᵀ of a mass matrix (Featherstone's LTDL: L follows
 *     the tree, no fill-in when parents precede children) on elements of type T (double, or
 *     a SIMD vector of states), as functions P##ldl_factor, P##ldl_apply, P##ldl_solve and
 *     P##ldl_apply_columns, each declared with the qualifiers Q. It walks the tree by the
 *     kernels' tables rd_depth (each coordinate's number of ancestors) and rd_ancestor
 *     (them, nearest first): loops of constant trip counts, which GCC unrolls completely
 *     (RD_UNROLL), so the solve is straight-line code along the tree, as fast as code
 *     generated unrolled (the SIMD blocks' former copy). Instantiated after the
 *     kernels (it reads RD_NV and the tables) by runtime.c on doubles (rd_ldl_...) and by
 *     simd.py on each instruction set's vectors (rds4_ldl_...): the same operations in the
 *     same order, so a SIMD lane is bit for bit the scalar solve. The instantiator defines
 *     P##pivot_bad(d) first: 1 if a pivot (of any lane) is not positive and finite.
 *   rd_parallel(range, work, rows, unit, threads): the thread pool of batches (the
 *     runtime's rows, the SIMD blocks, the derivatives' rows and pairs).
 */

#define RD_UNROLL _Pragma("GCC unroll 128")
#define RD_LDL_DEFINE(Q, P, T)                                                                  \
    /* M = Lᵀ D L in place (the strict lower triangle L, the diagonal D): 3 if M is not     \
     * positive definite. */                                                                 \
    Q int P##ldl_factor(T *M) {                                                              \
        const int n = RD_NV;                                                                 \
        RD_UNROLL for (int k = n - 1; k >= 0; --k) {                                         \
            const T d = M[k * n + k];                                                        \
            if (P##pivot_bad(d)) return 3;                                                   \
            RD_UNROLL for (int a = 0; a < rd_depth[k]; ++a) {                                \
                const int i = rd_ancestor[k][a];                                             \
                const T x = M[k * n + i] / d;                                                \
                M[i * n + i] -= M[k * n + i] * x;                                            \
                RD_UNROLL for (int b = 0; b < rd_depth[i]; ++b) {                            \
                    const int j = rd_ancestor[i][b];                                         \
                    M[i * n + j] -= M[k * n + j] * x;                                        \
                }                                                                            \
                M[k * n + i] = x;                                                            \
            }                                                                                \
        }                                                                                    \
        return 0;                                                                            \
    }                                                                                        \
    /* b -> M⁻¹ b with the factor of P##ldl_factor. */                                       \
    Q void P##ldl_apply(const T *M, T *b) {                                                  \
        const int n = RD_NV;                                                                 \
        RD_UNROLL for (int i = n - 1; i >= 0; --i) {                                         \
            RD_UNROLL for (int a = 0; a < rd_depth[i]; ++a) {                                \
                const int j = rd_ancestor[i][a];                                             \
                b[j] -= M[i * n + j] * b[i];                                                 \
            }                                                                                \
        }                                                                                    \
        RD_UNROLL for (int i = 0; i < n; ++i) b[i] /= M[i * n + i];                          \
        RD_UNROLL for (int i = 0; i < n; ++i) {                                              \
            RD_UNROLL for (int a = 0; a < rd_depth[i]; ++a) {                                \
                const int j = rd_ancestor[i][a];                                             \
                b[i] -= M[i * n + j] * b[j];                                                 \
            }                                                                                \
        }                                                                                    \
    }                                                                                        \
    /* B -> M⁻¹ B for k right-hand sides at once, B n×k row-major (B[j k + c] is b_c[j]):    \
     * each column gets P##ldl_apply's operations in its order (the same bits), the tree     \
     * walked once. */                                                                       \
    Q void P##ldl_apply_columns(const T *M, T *B, int k) {                                   \
        const int n = RD_NV;                                                                 \
        for (int i = n - 1; i >= 0; --i)                                                     \
            for (int a = 0; a < rd_depth[i]; ++a) {                                          \
                const int j = rd_ancestor[i][a];                                             \
                const T x = M[i * n + j];                                                    \
                for (int c = 0; c < k; ++c) B[j * k + c] -= x * B[i * k + c];                \
            }                                                                                \
        for (int i = 0; i < n; ++i) {                                                        \
            const T d = M[i * n + i];                                                        \
            for (int c = 0; c < k; ++c) B[i * k + c] /= d;                                   \
        }                                                                                    \
        for (int i = 0; i < n; ++i)                                                          \
            for (int a = 0; a < rd_depth[i]; ++a) {                                          \
                const int j = rd_ancestor[i][a];                                             \
                const T x = M[i * n + j];                                                    \
                for (int c = 0; c < k; ++c) B[i * k + c] -= x * B[j * k + c];                \
            }                                                                                \
    }                                                                                        \
    /* Solve M x = b in place (b -> x), M destroyed; 3 if M is not positive definite. */     \
    Q int P##ldl_solve(T *M, T *b) {                                                         \
        if (P##ldl_factor(M)) return 3;                                                      \
        P##ldl_apply(M, b);                                                                  \
        return 0;                                                                            \
    }

/* ---- the thread pool -------------------------------------------------------------------- */
#define RD_MIN_ROWS_PER_THREAD 64
#define RD_MAX_THREADS 256

/* Rows [begin, end) of a batch's work: the worst row status (0 all well). */
typedef int (*rd_range)(const void *work, Py_ssize_t begin, Py_ssize_t end);

typedef struct {
    rd_range range;
    const void *work;
    Py_ssize_t begin, end;
    int status;
} rd_share;

static void *rd_share_run(void *arg) {
    rd_share *share = (rd_share *)arg;
    share->status = share->range(share->work, share->begin, share->end);
    return NULL;
}

/* Rows [0, rows) on up to `threads` POSIX threads (the calling one included; at least
 * RD_MIN_ROWS_PER_THREAD rows a thread), split into ranges of whole units of `unit` rows
 * (a SIMD block's lanes) but the last; the worst status of every range. A thread that cannot
 * start has its rows done by the calling thread. */
__attribute__((unused)) static int rd_parallel(rd_range range, const void *work, Py_ssize_t rows, Py_ssize_t unit,
                                               long threads) {
    if (threads > RD_MAX_THREADS) threads = RD_MAX_THREADS;
    if (threads > rows / RD_MIN_ROWS_PER_THREAD) threads = (long)(rows / RD_MIN_ROWS_PER_THREAD);
    if (threads < 1) threads = 1;
    rd_share shares[RD_MAX_THREADS];
    pthread_t ids[RD_MAX_THREADS];
    int started[RD_MAX_THREADS];
    const Py_ssize_t blocks = rows / unit;
    for (long k = 0; k < threads; ++k) {
        shares[k].range = range;
        shares[k].work = work;
        shares[k].begin = blocks * k / threads * unit;
        shares[k].end = k + 1 == threads ? rows : blocks * (k + 1) / threads * unit;
        shares[k].status = 0;
        started[k] = 0;
    }
    for (long k = 1; k < threads; ++k) started[k] = pthread_create(&ids[k], NULL, rd_share_run, &shares[k]) == 0;
    rd_share_run(&shares[0]);
    int worst = shares[0].status;
    for (long k = 1; k < threads; ++k) {
        if (started[k])
            pthread_join(ids[k], NULL);
        else
            rd_share_run(&shares[k]); /* could not start a thread: do its rows here */
        if (shares[k].status > worst) worst = shares[k].status;
    }
    return worst;
}
