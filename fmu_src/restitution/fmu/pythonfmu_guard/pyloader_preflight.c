/*
 * pyloader_preflight.c - the Python code the loader (python_loader.c) runs in an interpreter a guard
 * started: it puts the site-packages directories recorded in resources/python_env.txt on sys.path,
 * checks that the required modules import (a message naming what is missing and how to fix it, else)
 * and marks the interpreter as a guard's, so that another FMU's guard recognizes it.
 */
#ifndef _GNU_SOURCE
#define _GNU_SOURCE
#endif
#include "pyloader_internal.h"

#include <limits.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Python bytes literal for an arbitrary path: b'\x2f...' then os.fsdecode() */
static void py_bytes_literal(const char *s, char *out, size_t size)
{
    size_t n = 0;
    if (size < 4) return;
    out[n++] = 'b';
    out[n++] = '\'';
    for (const unsigned char *p = (const unsigned char *)s; *p && n + 6 < size; p++) {
        if ((*p >= 'a' && *p <= 'z') || (*p >= 'A' && *p <= 'Z') || (*p >= '0' && *p <= '9') || *p == '/' ||
            *p == '.' || *p == '_' || *p == '-')
            out[n++] = (char)*p;
        else
            n += (size_t)snprintf(out + n, size - n, "\\x%02x", *p);
    }
    out[n++] = '\'';
    out[n] = '\0';
}

/* ------------------------------------------------------------------------ */
/* Preflight: put the recorded site-packages on sys.path, check that the    */
/* required modules import. Runs with the GIL held. Returns a message       */
/* starting with "E:" (fatal), "W:" (warning) or "" in msg.                 */
/* ------------------------------------------------------------------------ */
static const char PREFLIGHT_CODE[] =
    "def _pythonfmu_native_host_preflight(cfg_path, res_dir):\n"
    "    import os, sys, site\n"
    "    sites, requires = [], []\n"
    "    with open(cfg_path, 'r', encoding='utf-8', errors='surrogateescape') as f:\n"
    "        for raw in f:\n"
    "            line = raw.strip()\n"
    "            if not line or line.startswith('#') or '=' not in line:\n"
    "                continue\n"
    "            key, value = (s.strip() for s in line.split('=', 1))\n"
    "            if key == 'site' and value:\n"
    "                sites.append(value)\n"
    "            elif key == 'require':\n"
    "                requires.extend(m.strip() for m in value.split(',') if m.strip())\n"
    "    missing_dirs = [d for d in sites if not os.path.isdir(d)]\n"
    "    for d in sites:\n"
    "        if d not in missing_dirs and d not in sys.path:\n"
    "            site.addsitedir(d)\n"
    "    failed = []\n"
    "    for mod in requires:\n"
    "        try:\n"
    "            __import__(mod)\n"
    "        except BaseException as exc:\n"
    "            failed.append('%s (%s: %s)' % (mod, type(exc).__name__, exc))\n"
    "    sys._pythonfmu_native_host = True\n"
    "    req_txt = os.path.join(res_dir, 'requirements.txt')\n"
    "    if failed:\n"
    "        lines = ['this FMU needs Python modules that the embedded interpreter cannot import: '\n"
    "                 + '; '.join(failed) + '.',\n"
    "                 'Interpreter: %s (Python %s), sys.prefix=%s.' % (sys.executable,\n"
    "                 sys.version.split()[0], sys.prefix)]\n"
    "        if missing_dirs:\n"
    "            lines.append('site-packages directories recorded at build time that no longer exist: '\n"
    "                         + ', '.join(missing_dirs) + '.')\n"
    "        lines.append('sys.path=%r.' % (sys.path,))\n"
    "        inst = 'requirements.txt (' + req_txt + ')' if os.path.isfile(req_txt) else 'the packages providing: ' + ', '.join(m.split(' ')[0] for m in failed)\n"
    "        lines.append('Fix: install ' + inst + ' into that Python environment (' + sys.executable\n"
    "                     + ' -m pip install ...), or edit ' + cfg_path + ' (executable=, libpython=, site= lines)'\n"
    "                     + ' to point to a Python environment that has them.')\n"
    "        return 'E:' + ' '.join(lines)\n"
    "    if missing_dirs:\n"
    "        return 'W:site-packages directories recorded in %s do not exist: %s' % (cfg_path, ', '.join(missing_dirs))\n"
    "    return ''\n"
    "import sys as _pfmu_sys\n"
    "try:\n"
    "    _pfmu_sys._pythonfmu_native_host_msg = _pythonfmu_native_host_preflight(\n"
    "        __import__('os').fsdecode(@CFG@), __import__('os').fsdecode(@RES@))\n"
    "except BaseException as _pfmu_exc:\n"
    "    _pfmu_sys._pythonfmu_native_host_msg = 'E:preflight check failed: %r' % (_pfmu_exc,)\n"
    "del _pythonfmu_native_host_preflight, _pfmu_sys\n";

/* copy src to dst replacing the first occurrence of token by value */
static void replace_token(char *dst, size_t size, const char *src, const char *token, const char *value)
{
    const char *at = strstr(src, token);
    if (!at) {
        snprintf(dst, size, "%s", src);
        return;
    }
    snprintf(dst, size, "%.*s%s%s", (int)(at - src), src, value, at + strlen(token));
}

void pyloader_run_preflight(const char *cfg_file, const char *res_dir, char *msg, size_t size)
{
    char lit_cfg[4 * PATH_MAX + 8], lit_res[4 * PATH_MAX + 8];
    py_bytes_literal(cfg_file, lit_cfg, sizeof lit_cfg);
    py_bytes_literal(res_dir, lit_res, sizeof lit_res);
    size_t n = sizeof PREFLIGHT_CODE + strlen(lit_cfg) + strlen(lit_res) + 16;
    char *tmp = malloc(n), *code = malloc(n);
    msg[0] = '\0';
    if (!tmp || !code) {
        free(tmp);
        free(code);
        snprintf(msg, size, "E:out of memory");
        return;
    }
    replace_token(tmp, n, PREFLIGHT_CODE, "@CFG@", lit_cfg);
    replace_token(code, n, tmp, "@RES@", lit_res);
    free(tmp);
    int rc = pyloader_py.PyRun_SimpleStringFlags(code, NULL);
    free(code);
    if (rc != 0) {
        snprintf(msg, size, "E:the preflight Python code failed (traceback on stderr)");
        return;
    }
    PyObj *sys = pyloader_py.PyImport_ImportModule("sys");
    if (!sys) {
        pyloader_py.PyErr_Clear();
        if (!msg[0]) snprintf(msg, size, "E:cannot import sys");
        return;
    }
    PyObj *m = pyloader_py.PyObject_GetAttrString(sys, "_pythonfmu_native_host_msg");
    if (m) {
        const char *s = pyloader_py.PyUnicode_AsUTF8(m);
        if (s) snprintf(msg, size, "%s", s);
        pyloader_py.Py_DecRef(m);
    }
    pyloader_py.PyErr_Clear();
    pyloader_py.Py_DecRef(sys);
}

/* Is the running interpreter one started by a guard (marker set in preflight)? */
int pyloader_interpreter_is_guard_managed(void)
{
    int managed = 0;
    int gil = pyloader_py.PyGILState_Ensure();
    PyObj *sys = pyloader_py.PyImport_ImportModule("sys");
    if (sys) {
        PyObj *marker = pyloader_py.PyObject_GetAttrString(sys, "_pythonfmu_native_host");
        if (marker) {
            managed = 1;
            pyloader_py.Py_DecRef(marker);
        }
        pyloader_py.Py_DecRef(sys);
    }
    pyloader_py.PyErr_Clear();
    pyloader_py.PyGILState_Release(gil);
    return managed;
}
