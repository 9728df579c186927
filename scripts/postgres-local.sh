#!/usr/bin/env bash
# A private PostgreSQL cluster in a directory of its own, for tests and for running several daemons
# on one machine without Docker (issue 18). It listens only on a Unix socket in DIR (no TCP port,
# so clusters never collide) and trusts local connections of the user "devsurf".
#
# Usage:
#   scripts/postgres-local.sh start DIR [--fast]   initdb if needed, start, create database
#                                                  "devsurf"; prints the libpq URI on stdout.
#                                                  --fast: fsync off (tests: the data dies with DIR)
#   scripts/postgres-local.sh stop DIR             stop it (fast shutdown); DIR stays
#   scripts/postgres-local.sh destroy DIR          stop it and remove DIR
#   scripts/postgres-local.sh uri DIR              print the URI
#
# PostgreSQL refuses to run as root: run as root, the server runs as the "postgres" account that
# Debian's package creates, and DIR is made reachable for it (DIR must not lie under a directory
# that account cannot enter; /tmp is fine).
set -euo pipefail

command=${1:-}
dir=${2:-}
if [ -z "$command" ] || [ -z "$dir" ]; then
  sed -n '2,16p' "$0" >&2
  exit 2
fi
case "$dir" in /*) ;; *) dir="$PWD/$dir" ;; esac  # the server commands run from /
fast=0
[ "${3:-}" = "--fast" ] && fast=1

bindir=$(ls -d /usr/lib/postgresql/*/bin 2>/dev/null | sort -V | tail -n 1)
if [ -z "$bindir" ] || [ ! -x "$bindir/initdb" ]; then
  echo "postgres-local: no PostgreSQL server found (apt-get install postgresql; scripts/setup.sh does)" >&2
  exit 1
fi

as_server() {
  if [ "$(id -u)" -eq 0 ]; then
    # From / : the caller's directory may be one the postgres account cannot enter.
    (cd / && runuser -u postgres -- "$@")
  else
    "$@"
  fi
}

uri() { echo "postgresql://devsurf@/devsurf?host=$dir"; }

case "$command" in
  start)
    mkdir -p "$dir"
    dir=$(cd "$dir" && pwd)
    if [ "$(id -u)" -eq 0 ]; then
      chown postgres: "$dir"
      chmod 0755 "$dir"
    fi
    if [ ! -f "$dir/data/PG_VERSION" ]; then
      rm -rf "$dir/data"
      as_server "$bindir/initdb" -D "$dir/data" -U devsurf --auth=trust --encoding=UTF8 --locale=C.UTF-8 \
        > "$dir/initdb.log" 2>&1 || { cat "$dir/initdb.log" >&2; exit 1; }
    fi
    if ! as_server "$bindir/pg_ctl" -D "$dir/data" status > /dev/null 2>&1; then
      options="-c listen_addresses='' -c unix_socket_directories='$dir' -c max_connections=200"
      [ "$fast" = 1 ] && options="$options -c fsync=off -c synchronous_commit=off -c full_page_writes=off"
      as_server "$bindir/pg_ctl" -D "$dir/data" -l "$dir/server.log" -w -t 60 -o "$options" start > /dev/null \
        || { tail -n 30 "$dir/server.log" >&2; exit 1; }
    fi
    if [ "$(as_server "$bindir/psql" -h "$dir" -U devsurf -d postgres -tAc \
          "SELECT 1 FROM pg_database WHERE datname = 'devsurf'")" != 1 ]; then
      as_server "$bindir/createdb" -h "$dir" -U devsurf devsurf
    fi
    uri
    ;;
  stop)
    [ -f "$dir/data/PG_VERSION" ] || exit 0
    as_server "$bindir/pg_ctl" -D "$dir/data" -m fast -w stop > /dev/null 2>&1 || true
    ;;
  destroy)
    if [ -f "$dir/data/PG_VERSION" ]; then
      as_server "$bindir/pg_ctl" -D "$dir/data" -m immediate -w stop > /dev/null 2>&1 || true
    fi
    rm -rf "$dir"
    ;;
  uri)
    dir=$(cd "$dir" && pwd)
    uri
    ;;
  *)
    echo "postgres-local: unknown command $command" >&2
    exit 2
    ;;
esac
