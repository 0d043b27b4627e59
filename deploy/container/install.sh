#!/bin/sh
# Run by the Containerfile's one RUN step inside the image being built (docs/operations.md,
# "Containers and Kubernetes"): installs plcemu from its Debian package, makes the user the
# daemon runs as and the state directory, writes the container's /etc/plcemu/plcemud.yaml and
# leaves no package lists or caches behind.
# Usage: install.sh PACKAGE.deb UID
set -eu
deb=$1
uid=$2
here=$(dirname "$0")
export DEBIAN_FRONTEND=noninteractive

# A slim base (debian:bookworm-slim, or scripts/container.sh's) drops /usr/share/doc; keep the
# example configurations. dpkg reads dpkg.cfg.d in name order, so this comes after the exclusion.
echo 'path-include=/usr/share/doc/plcemu/examples/*' >/etc/dpkg/dpkg.cfg.d/plcemu-examples

# A base that already holds the package's dependencies (scripts/container.sh makes one) needs no
# package lists, and so no network; otherwise fetch the lists and the dependencies.
if ! apt-get install -y -q --no-install-recommends "$deb" >/tmp/apt.log 2>&1; then
    apt-get update -q
    apt-get install -y -q --no-install-recommends "$deb"
fi
rm -f /tmp/apt.log

# The daemon's user and group, fixed ids; the state directory is its only writable place.
groupadd --system --gid "$uid" plcemu
useradd --system -K SYS_UID_MAX="$uid" --uid "$uid" --gid plcemu --no-create-home \
    --home-dir /var/lib/plcemu --shell /usr/sbin/nologin plcemu
install -d -o plcemu -g plcemu -m 0750 /var/lib/plcemu

# The container's configuration: the package's default example (an FBs-24MC running the FBs
# manual's FUN86 example, ten heating loops) listening on every address of the container, its
# leading comment (how to run it from the source tree) replaced by one about the image.
examples=/usr/share/doc/plcemu/examples
test -f "$examples/default.yaml"
{
    cat "$here/plcemud.yaml.head"
    awk 'body || (!/^#/ && !/^[ \t]*$/) { body = 1; print }' "$examples/default.yaml" |
        sed 's/^\([ \t]*bind:[ \t]*\)127\.0\.0\.1/\10.0.0.0/'
} >/etc/plcemu/plcemud.yaml.new
mv /etc/plcemu/plcemud.yaml.new /etc/plcemu/plcemud.yaml
chmod 0644 /etc/plcemu/plcemud.yaml
if grep -q '^[ \t]*bind:[ \t]*127\.' /etc/plcemu/plcemud.yaml; then
    echo "install.sh: /etc/plcemu/plcemud.yaml still binds a loopback address" >&2
    exit 1
fi

install -d /usr/libexec/plcemu
install -m 0755 "$here/entrypoint" "$here/healthcheck" /usr/libexec/plcemu/

# Nothing of apt's or dpkg's working files: lists, caches, logs.
apt-get clean
rm -rf /var/lib/apt/lists/* /var/cache/apt/* /var/cache/debconf/*-old /var/lib/dpkg/*-old \
    /var/log/apt /var/log/dpkg.log /var/log/alternatives.log
