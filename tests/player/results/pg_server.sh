#!/usr/bin/env bash
# A throw-away PostgreSQL server for the results tests (CTest fixture viscera_postgres):
#   pg_server.sh start STATE_DIR   initdb + pg_ctl start in a fresh /tmp folder, listening on a unix
#                                  socket only (no TCP); writes STATE_DIR/conninfo ("host=… user=…
#                                  dbname=postgres") for the tests, who make their own databases.
#   pg_server.sh stop STATE_DIR    stops it and removes its folder.
# Run as root, the server runs as the user postgres (or nobody) in a folder that user owns.
# Any failure exits non-zero: the fixture's setup test fails, never a silent skip.
set -euo pipefail
cmd=${1:?usage: pg_server.sh start|stop STATE_DIR}
state=${2:?usage: pg_server.sh start|stop STATE_DIR}

bindir=$(ls -d /usr/lib/postgresql/*/bin 2>/dev/null | sort -V | tail -n1 || true)
if [[ -z "$bindir" || ! -x "$bindir/initdb" ]]; then
  echo "pg_server.sh: no PostgreSQL server found under /usr/lib/postgresql/*/bin (install postgresql)" >&2
  exit 1
fi

as_owner() {
  if [[ $(id -u) -eq 0 ]]; then
    runuser -u "$owner" -- "$@"
  else
    "$@"
  fi
}

stop() {
  [[ -f "$state/dir" ]] || return 0
  local dir
  dir=$(cat "$state/dir")
  owner=$(stat -c %U "$dir" 2>/dev/null || echo root)
  if [[ -d "$dir/data" ]]; then
    as_owner "$bindir/pg_ctl" -D "$dir/data" -m fast -w stop >/dev/null 2>&1 || true
  fi
  rm -rf "$dir"
  rm -f "$state/dir" "$state/conninfo"
}

case "$cmd" in
start)
  mkdir -p "$state"
  stop # a server left by an interrupted run
  dir=$(mktemp -d /tmp/viscera-pg.XXXXXX)
  echo "$dir" >"$state/dir"
  owner=$(id -un)
  if [[ $(id -u) -eq 0 ]]; then
    owner=postgres
    getent passwd postgres >/dev/null || owner=nobody
    chown "$owner" "$dir"
  fi
  as_owner "$bindir/initdb" -D "$dir/data" -U viscera --auth=trust -E UTF8 --locale=C.UTF-8 >"$dir/initdb.log" 2>&1 ||
    { cat "$dir/initdb.log" >&2; echo "pg_server.sh: initdb failed" >&2; exit 1; }
  as_owner "$bindir/pg_ctl" -D "$dir/data" -l "$dir/server.log" -w -t 60 \
    -o "-c listen_addresses='' -k $dir -c fsync=off -c max_connections=40" start >/dev/null ||
    { cat "$dir/server.log" >&2; echo "pg_server.sh: the server did not start" >&2; exit 1; }
  conninfo="host=$dir port=5432 user=viscera dbname=postgres"
  "$bindir/pg_isready" -q -h "$dir" -p 5432 -t 30 || { echo "pg_server.sh: the server at $dir does not answer" >&2; exit 1; }
  echo "$conninfo" >"$state/conninfo"
  echo "pg_server.sh: PostgreSQL $("$bindir/postgres" --version | awk '{print $3}') on $dir (unix socket only)"
  ;;
stop)
  stop
  ;;
*)
  echo "usage: pg_server.sh start|stop STATE_DIR" >&2
  exit 2
  ;;
esac
