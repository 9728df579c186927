# PostgreSQL from Debian's package, for docker/compose.scale.yml (the shared store of several
# devsurf daemons). The cluster is made on first start in the volume; DEVSURF_DB_PASSWORD is the
# password of the role "devsurf" that owns the database "devsurf".
FROM debian:12
ENV DEBIAN_FRONTEND=noninteractive
RUN apt-get update -q && apt-get install -y -q --no-install-recommends postgresql-15 && rm -rf /var/lib/apt/lists/*
COPY docker/scale/postgres-entrypoint.sh /usr/local/bin/postgres-entrypoint.sh
VOLUME /var/lib/postgresql/data
EXPOSE 5432
USER postgres
HEALTHCHECK --interval=5s --timeout=3s CMD /usr/lib/postgresql/15/bin/pg_isready -h 127.0.0.1 -U devsurf -d devsurf
ENTRYPOINT ["/usr/local/bin/postgres-entrypoint.sh"]
