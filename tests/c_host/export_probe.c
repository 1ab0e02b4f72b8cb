/* One function exported and one kept inside, as the native FMUs do it (the FMI headers' FMI2_Export /
 * FMI3_Export, everything else hidden by -fvisibility=hidden or, on Windows, by exporting only what
 * __declspec(dllexport) names): tests/fmu/test_cross_binaries.py builds it for every platform to check
 * that tests/binary_formats.py reads exactly that export from each format. */
#if defined(_WIN32)
#define PROBE_EXPORT __declspec(dllexport)
#else
#define PROBE_EXPORT __attribute__((visibility("default")))
#endif

int probe_internal(int x);

int probe_internal(int x)
{
    return 2 * x;
}

PROBE_EXPORT int probe_exported(int x);

PROBE_EXPORT int probe_exported(int x)
{
    return probe_internal(x) + 1;
}
