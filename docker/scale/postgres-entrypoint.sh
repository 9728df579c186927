#!/bin/sh
# First start: initdb, the role and database devsurf, password authentication from the compose
# network. Every start: the server in the foreground.
set -eu
bin=/usr/lib/postgresql/15/bin
data=${PGDATA:-/var/lib/postgresql/data}
if [ ! -f "$data/PG_VERSION" ]; then
  : "${DEVSURF_DB_PASSWORD:?set DEVSURF_DB_PASSWORD}"
  "$bin/initdb" -D "$data" -U postgres --auth-local=peer --auth-host=scram-sha-256 --encoding=UTF8 --locale=C.UTF-8
  echo "host all all 0.0.0.0/0 scram-sha-256" >> "$data/pg_hba.conf"
  "$bin/pg_ctl" -D "$data" -o "-c listen_addresses=''" -w start
  psql -v ON_ERROR_STOP=1 -d postgres -c "CREATE ROLE devsurf LOGIN PASSWORD '$DEVSURF_DB_PASSWORD'" \
       -c "CREATE DATABASE devsurf OWNER devsurf"
  "$bin/pg_ctl" -D "$data" -m fast -w stop
fi
exec "$bin/postgres" -D "$data" -c listen_addresses='*' -c max_connections=200
