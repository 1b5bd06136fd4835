"""The FMUs' Windows binaries checked from Linux, by ctest in the normal build:

  windows_fmu.py prefix                    make the Wine prefix ($WINEPREFIX) once
  windows_fmu.py tables X.fmu...           each DLL's import and export tables
  windows_fmu.py same-results X.fmu IMPORTER IMPORTER.exe
                                           the drop test on the Linux and the Windows binary
  windows_fmu.py same-exported-results IMPORTER IMPORTER.exe
                                           the same for an exported FMU (fraccontact export, its fixed
                                           values read from its resources through a file: URI each)
  windows_fmu.py stop                      end the Wine server, so that ctest does not wait for it

Wine runs in the environment ctest gives (WINEPREFIX inside the build folder)."""

import os
import re
import shutil
import subprocess
import sys
import tempfile
import zipfile

# What every Windows has: the kernel and a C runtime (msvcrt.dll, or the
# Universal CRT with its api-ms-win-crt-* forwarders).
SYSTEM_DLLS = {"kernel32.dll", "msvcrt.dll", "ucrtbase.dll"}


def is_system_dll(name):
    return name.lower() in SYSTEM_DLLS or name.lower().startswith("api-ms-win-crt-")


def need(program, package):
    path = shutil.which(program)
    if not path:
        sys.exit(f"{program} is not on PATH: run scripts/setup (it installs Debian's {package})")
    return path


def binaries(fmu, folder):
    """The FMU unpacked into folder: its Linux .so and its Windows .dll."""
    zipfile.ZipFile(fmu).extractall(folder)
    found = {}
    for platform in sorted(os.listdir(os.path.join(folder, "binaries"))):
        for name in os.listdir(os.path.join(folder, "binaries", platform)):
            found.setdefault(os.path.splitext(name)[1], []).append(os.path.join(folder, "binaries", platform, name))
    if len(found.get(".so", [])) != 1 or len(found.get(".dll", [])) != 1:
        sys.exit(f"{fmu}: want one Linux .so and one Windows .dll under binaries/, found {found}")
    return found[".so"][0], found[".dll"][0]


def dll_tables(dll):
    """The DLLs a DLL imports from, and the names it exports (objdump -p)."""
    out = subprocess.run([need("x86_64-w64-mingw32-objdump", "binutils-mingw-w64-x86-64"), "-p", dll],
                         check=True, capture_output=True, text=True).stdout
    imports = re.findall(r"^\s*DLL Name: (\S+)", out, re.M)
    table = out.split("[Ordinal/Name Pointer] Table", 1)
    exports = re.findall(r"^\s*\[\s*\d+\] (\S+)$", table[1].split("\n\n", 1)[0], re.M) if len(table) == 2 else []
    return imports, exports


def so_exports(so):
    out = subprocess.run(["nm", "-D", "--defined-only", so], check=True, capture_output=True, text=True).stdout
    return {line.split()[-1] for line in out.splitlines() if line.split()[1] in "TtDdBbRr"}


def tables(fmus):
    failed = False
    for fmu in fmus:
        with tempfile.TemporaryDirectory() as folder:
            so, dll = binaries(fmu, folder)
            imports, exports = dll_tables(dll)
            linux = so_exports(so)
            name = os.path.relpath(dll, folder)
            print(f"{os.path.basename(fmu)}: {name} imports {', '.join(imports)}; exports {len(exports)} names")
            strange = [i for i in imports if not is_system_dll(i)]
            if not imports or strange:
                print(f"  imports DLLs beyond the kernel and the C runtime: {strange or 'none found'}")
                failed = True
            # The FMI functions and nothing else: the Linux binary's exports,
            # which test_fmu_compliance.py holds to the fmi prefix.
            if set(exports) != linux or not all(e.startswith("fmi") for e in exports):
                print(f"  exports beyond the FMI functions: {sorted(set(exports) - linux)}; "
                      f"missing: {sorted(linux - set(exports))}")
                failed = True
    return failed


def prefix():
    """Make the prefix, and keep its server and services running until
    'stop' (or for 30 s after the last Wine program, should 'stop' never
    come), so that each test's Wine starts in 0.1 s, not 3 s. They outlive
    this call, so they must not hold its output open (ctest would wait for
    them): they write to a log, shown when the prefix fails."""
    wine, wineserver = need("wine", "wine and wine64"), need("wineserver", "wine")
    log_path = os.environ["WINEPREFIX"] + ".log"
    os.makedirs(os.environ["WINEPREFIX"], exist_ok=True)  # the server's working directory
    with open(log_path, "w") as log:
        # Fails when a server runs already (left by an interrupted run): it serves as well.
        subprocess.run([wineserver, "-p30"], stdout=log, stderr=log)
        boot = subprocess.run([wine, "wineboot", "--init"], stdin=subprocess.DEVNULL, stdout=log, stderr=log,
                              timeout=300)
    if boot.returncode:
        print(open(log_path).read())
        return 1
    return 0


def exported_results(importer, importer_exe):
    """An FMU exported with values other than the defaults (python -m fraccontact export, on
    $FRACCONTACT_FMU): its Linux and Windows binaries give the same results, the full FMU's Linux binary
    others (the file is read, on Windows from a file:///Z:/ URI, Wine's drive of /)."""
    import pathlib
    with tempfile.TemporaryDirectory() as folder:
        fmu = os.path.join(folder, "exported.fmu")
        subprocess.run([sys.executable, "-m", "fraccontact", "export", fmu, "--c", "5000", "--k", "3e8"],
                       check=True, capture_output=True)
        with zipfile.ZipFile(fmu) as z:
            guid = re.search(r'guid="([^"]+)"', z.read("modelDescription.xml").decode()).group(1)
        unpacked = os.path.join(folder, "unpacked")
        so, dll = binaries(fmu, unpacked)
        resources = pathlib.Path(unpacked, "resources")
        linux = results([importer, so, "1", resources.as_uri(), guid])
        windows = results([need("wine", "wine and wine64"), importer_exe, dll, "1",
                           "file:///Z:" + resources.as_posix(), guid])
        full = results([importer, so])
    for name in linux:
        print(f"{name:16} Linux {linux[name]!r:24} Windows {windows[name]!r:24} full {full[name]!r}")
    return linux != windows or linux["F_peak"] == full["F_peak"]


def results(command):
    done = subprocess.run(command, capture_output=True, text=True, timeout=120)
    if done.returncode != 0:
        sys.exit(f"{' '.join(command)} failed ({done.returncode}):\n{done.stdout}{done.stderr}")
    return {name: float(value) for name, value in (line.split() for line in done.stdout.splitlines())}


def same_results(fmu, importer, importer_exe):
    with tempfile.TemporaryDirectory() as folder:
        so, dll = binaries(fmu, folder)
        linux = results([importer, so])
        windows = results([need("wine", "wine and wine64"), importer_exe, dll])
    # The same source, compiler (GCC 12) and SSE2 arithmetic on both: only the
    # C libraries differ, in pow, exp, log1p and tgamma (the G1 sum's factor
    # and weights; the Hertz force uses sqrt, correctly rounded on both). Were
    # one of them off by an ulp somewhere, the difference would walk like
    # sqrt(n) ulp over the n = 13 160 internal steps of the impact: 2.5e-14;
    # 1e-13 is 4x that (as test_fmu_compliance.py allows a rebuilt binary).
    # Measured: identical, to the last digit.
    failed = False
    for name in linux:
        diff = abs(windows[name] - linux[name]) / max(abs(linux[name]), 1e-300)
        verdict = "identical" if windows[name] == linux[name] else f"rel. difference {diff:.3g}"
        print(f"{name:16} Linux {linux[name]!r:24} Windows {windows[name]!r:24} {verdict}")
        failed |= not diff <= 1e-13
    return failed or set(linux) != set(windows)


def main(argv):
    if argv[:1] == ["prefix"]:
        return prefix()
    if argv[:1] == ["tables"] and len(argv) > 1:
        return tables(argv[1:])
    if argv[:1] == ["same-results"] and len(argv) == 4:
        return same_results(*argv[1:])
    if argv[:1] == ["same-exported-results"] and len(argv) == 3:
        return exported_results(*argv[1:])
    if argv[:1] == ["stop"]:
        subprocess.run([need("wineserver", "wine"), "-k"])  # fails when no server runs: fine
        return 0
    sys.exit(__doc__)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
