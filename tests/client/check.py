"""Client generation check (tests/client/check.sh runs it with the pinned generators).

1. openapi-python-client generates a client from openapi/openapi.json: no warning at all, and
   one module per operationId of the document (none dropped).
2. openapi-typescript generates types from it: nothing on stderr but its banner, and one entry
   of `operations` per operationId.
3. The MES script (tests/client/mes_example.py) drives the real motiond through the generated
   Python client: started on a free loopback port with a temporary database.

Prints `client-generation: N operations, 0 warnings` and exits non-zero on any failure.
"""

import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import threading
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
DOC = ROOT / "openapi" / "openapi.json"
OUT = ROOT / "target" / "client"
PACKAGE = OUT / "python" / "motiond_client"


def fail(msg: str) -> None:
    print(f"client-generation: FAILED: {msg}", file=sys.stderr)
    sys.exit(1)


def operation_ids() -> set[str]:
    doc = json.loads(DOC.read_text())
    ids = set()
    for path, item in doc["paths"].items():
        for method, op in item.items():
            if method in ("get", "put", "post", "delete", "patch", "head", "options", "trace"):
                if "operationId" not in op:
                    fail(f"{method.upper()} {path} has no operationId")
                ids.add(op["operationId"])
    return ids


def python_client(ids: set[str]) -> int:
    shutil.rmtree(PACKAGE, ignore_errors=True)
    PACKAGE.parent.mkdir(parents=True, exist_ok=True)
    venv_bin = Path(sys.executable).parent
    env = dict(os.environ, PATH=f"{venv_bin}{os.pathsep}{os.environ['PATH']}", NO_COLOR="1")
    r = subprocess.run(
        [str(venv_bin / "openapi-python-client"), "generate", "--path", str(DOC), "--meta", "none",
         "--output-path", str(PACKAGE)],
        capture_output=True, text=True, env=env,
    )
    out = (r.stdout + r.stderr).strip()
    lines = [l for l in out.splitlines() if l.strip() and l.strip() != f"Generating {PACKAGE}"]
    if r.returncode != 0 or lines:
        fail(f"openapi-python-client (exit {r.returncode}) said:\n{out}")
    generated = {p.stem for p in (PACKAGE / "api").glob("*/*.py") if p.stem != "__init__"}
    missing, extra = ids - generated, generated - ids
    if missing or extra:
        fail(f"python client: operations missing {sorted(missing)}, unexpected {sorted(extra)}")
    return len(generated)


def typescript(ids: set[str]) -> int:
    bin_ = ROOT / "frontend" / "node_modules" / "openapi-typescript" / "bin" / "cli.js"
    if not bin_.exists():
        fail(f"{bin_} missing: run `npm ci` in frontend/ first")
    out = OUT / "schema.d.ts"
    r = subprocess.run(["node", str(bin_), str(DOC), "-o", str(out)], capture_output=True, text=True,
                       env=dict(os.environ, NO_COLOR="1", FORCE_COLOR="0"))
    noise = [l for l in (r.stdout + r.stderr).splitlines()
             if l.strip() and "openapi-typescript" not in l and "→" not in l]
    if r.returncode != 0 or noise:
        fail(f"openapi-typescript (exit {r.returncode}) said:\n{r.stdout}{r.stderr}")
    text = out.read_text()
    m = re.search(r"^export interface operations \{\n(.*?)^\}", text, re.S | re.M)
    if not m:
        fail("openapi-typescript wrote no `operations`")
    generated = set(re.findall(r"^    (\w+): \{", m.group(1), re.M))
    missing, extra = ids - generated, generated - ids
    if missing or extra:
        fail(f"typescript: operations missing {sorted(missing)}, unexpected {sorted(extra)}")
    return len(generated)


def mes_example() -> None:
    motiond = Path(os.environ.get("MOTIOND_BIN", ROOT / "target" / "debug" / "motiond"))
    if not motiond.exists():
        fail(f"{motiond} missing: run `cargo build -p motiond` first, or set MOTIOND_BIN")
    with tempfile.TemporaryDirectory(prefix="motiond-mes-") as tmp:
        p = subprocess.Popen(
            [str(motiond), "serve", "--listen", "127.0.0.1:0", "--db", str(Path(tmp) / "mes.db")],
            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=dict(os.environ, NO_COLOR="1"),
        )
        log: list[str] = []
        addr: list[str] = []
        started = threading.Event()

        def read() -> None:
            for line in p.stdout:
                log.append(line.rstrip())
                m = re.search(r"listening on (http://\S+)", line)
                if m and not addr:
                    addr.append(m.group(1))
                    started.set()
            started.set()

        threading.Thread(target=read, daemon=True).start()
        try:
            if not started.wait(60) or not addr:
                fail("motiond did not start:\n" + "\n".join(log))
            env = dict(os.environ, PYTHONPATH=str(PACKAGE.parent))
            r = subprocess.run([sys.executable, str(ROOT / "tests" / "client" / "mes_example.py"), addr[0]],
                               env=env, timeout=120)
            if r.returncode != 0:
                fail("the MES script failed; motiond said:\n" + "\n".join(log[-30:]))
        finally:
            p.terminate()
            try:
                p.wait(10)
            except subprocess.TimeoutExpired:
                p.kill()


def mes_test_suite() -> None:
    """The example pytest suite of an MES team (tests/client/test_virtual_time.py): motiond in
    virtual time through the generated client."""
    motiond = Path(os.environ.get("MOTIOND_BIN", ROOT / "target" / "debug" / "motiond"))
    env = dict(os.environ, PYTHONPATH=str(PACKAGE.parent), MOTIOND_BIN=str(motiond))
    r = subprocess.run([sys.executable, "-m", "pytest", "-q", "-s", "-p", "no:cacheprovider",
                        str(ROOT / "tests" / "client" / "test_virtual_time.py")], env=env, timeout=300)
    if r.returncode != 0:
        fail("the MES test suite (pytest, virtual time) failed")


def main() -> None:
    ids = operation_ids()
    n_py = python_client(ids)
    n_ts = typescript(ids)
    print(f"client-generation: {len(ids)} operations, 0 warnings "
          f"(openapi-python-client: {n_py}, openapi-typescript: {n_ts})")
    mes_example()
    mes_test_suite()
    # Python client, TypeScript types, MES script, MES test suite (a failure has exited above).
    print("client-generation: 4 passed, 0 failed")


if __name__ == "__main__":
    main()
