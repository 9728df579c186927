# HAProxy from Debian's package, for docker/compose.scale.yml: one port in front of the daemons.
FROM debian:12
ENV DEBIAN_FRONTEND=noninteractive
RUN apt-get update -q && apt-get install -y -q --no-install-recommends haproxy && rm -rf /var/lib/apt/lists/*
COPY docker/scale/haproxy.cfg /etc/haproxy/haproxy.cfg
EXPOSE 8080
ENTRYPOINT ["haproxy", "-W", "-db", "-f", "/etc/haproxy/haproxy.cfg"]
