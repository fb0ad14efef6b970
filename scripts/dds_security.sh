#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Makes the certificates and signed documents of a secured DDS link (DDS Security: authentication, access control,
# encryption), one folder per participant, for the daemons' and the viewer's --dds-security DIR.
#
#   scripts/dds_security.sh OUT_DIR [ROLE[:NAME] ...]
#
# OUT_DIR/ca/ holds the identity CA and the permissions CA (keys included: keep them off the machines that run
# trials); each participant's folder OUT_DIR/NAME/ holds what that participant needs and nothing else:
#   identity_ca.pem  permissions_ca.pem  governance.p7s   the shared trust and the domain's rules
#   cert.pem  key.pem  permissions.p7s                    its identity and what it may publish and subscribe
# Roles (what each may do on the link's topics, docs/dds.md):
#   world       publishes frames, the world's info and the view; subscribes reports and controller statistics
#   controller  publishes reports and statistics; subscribes frames and the world's info
#   viewer      subscribes the view
#   observer    subscribes the link's topics and publishes nothing (a participant that may watch but not push)
# NAME defaults to the role. Without roles: world, controller and viewer. The governance document makes every topic
# signed and encrypted and admits no participant the identity CA has not certified. Valid for 10 years; an existing
# OUT_DIR/ca is reused, so more participants can be added later.
set -euo pipefail

usage() { sed -n '3,20p' "$0" | sed 's/^# \{0,1\}//'; }
case "${1:-}" in
  -h|--help) usage; exit 0 ;;
  "") usage >&2; exit 2 ;;
esac
out="$1"; shift
roles=("$@")
((${#roles[@]})) || roles=(world controller viewer)
command -v openssl >/dev/null || { echo "dds_security: openssl is missing (apt-get install openssl)" >&2; exit 1; }
for spec in "${roles[@]}"; do
  case "${spec%%:*}" in world|controller|viewer|observer) ;;
    *) echo "dds_security: a role is world, controller, viewer or observer, not '${spec%%:*}'" >&2; exit 2 ;;
  esac
done

days=3650
ca="$out/ca"
mkdir -p "$ca"
umask 077
# Two CAs, as the specification has them: one certifies identities, the other signs governance and permissions.
for which in identity permissions; do
  if [ ! -f "$ca/${which}_ca.pem" ]; then
    openssl req -x509 -newkey ec -pkeyopt ec_paramgen_curve:prime256v1 -nodes -days "$days" \
      -keyout "$ca/${which}_ca_key.pem" -out "$ca/${which}_ca.pem" -subj "/O=Impetus/CN=Impetus ${which} CA" 2>/dev/null
  fi
done

topics_xml() { for topic in "$@"; do printf '            <topic>%s</topic>\n' "$topic"; done; }
frames=impetus_plane_frame reports=impetus_haptic_report info=impetus_world_info stats=impetus_haptic_stats
view_scene=impetus_view_scene view_snapshot=impetus_view_snapshot

# Governance: every domain, authenticated participants only, every topic signed and encrypted. (Every domain is an
# id range with a minimum only: Cyclone DDS 0.10 does not parse one with a maximum.)
cat >"$ca/governance.xml" <<'XML'
<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
     xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_governance.xsd">
  <domain_access_rules>
    <domain_rule>
      <domains><id_range><min>0</min></id_range></domains>
      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>
      <enable_join_access_control>true</enable_join_access_control>
      <discovery_protection_kind>ENCRYPT</discovery_protection_kind>
      <liveliness_protection_kind>ENCRYPT</liveliness_protection_kind>
      <rtps_protection_kind>NONE</rtps_protection_kind>
      <topic_access_rules>
        <topic_rule>
          <topic_expression>*</topic_expression>
          <enable_discovery_protection>true</enable_discovery_protection>
          <enable_liveliness_protection>true</enable_liveliness_protection>
          <enable_read_access_control>true</enable_read_access_control>
          <enable_write_access_control>true</enable_write_access_control>
          <metadata_protection_kind>ENCRYPT</metadata_protection_kind>
          <data_protection_kind>ENCRYPT</data_protection_kind>
        </topic_rule>
      </topic_access_rules>
    </domain_rule>
  </domain_access_rules>
</dds>
XML
openssl smime -sign -in "$ca/governance.xml" -text -out "$ca/governance.p7s" \
  -signer "$ca/permissions_ca.pem" -inkey "$ca/permissions_ca_key.pem" 2>/dev/null

for spec in "${roles[@]}"; do
  role="${spec%%:*}"
  name="${spec#*:}"
  [ "$spec" = "$role" ] && name="$role"
  dir="$out/$name"
  mkdir -p "$dir"
  subject="/O=Impetus/CN=$name"
  openssl req -new -newkey ec -pkeyopt ec_paramgen_curve:prime256v1 -nodes -keyout "$dir/key.pem" \
    -out "$dir/request.csr" -subj "$subject" 2>/dev/null
  openssl x509 -req -in "$dir/request.csr" -CA "$ca/identity_ca.pem" -CAkey "$ca/identity_ca_key.pem" \
    -CAcreateserial -days "$days" -out "$dir/cert.pem" 2>/dev/null
  rm -f "$dir/request.csr"
  # The subject as the certificate states it, in the form the permissions document compares.
  subject_name="$(openssl x509 -in "$dir/cert.pem" -noout -subject -nameopt RFC2253 | sed 's/^subject=//')"
  case "$role" in
    world) publish=("$frames" "$info" "$view_scene" "$view_snapshot"); subscribe=("$reports" "$stats") ;;
    controller) publish=("$reports" "$stats"); subscribe=("$frames" "$info") ;;
    viewer) publish=(); subscribe=("$view_scene" "$view_snapshot") ;;
    observer) publish=(); subscribe=("$frames" "$info" "$reports" "$stats" "$view_scene" "$view_snapshot") ;;
  esac
  {
    cat <<XML
<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
     xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_permissions.xsd">
  <permissions>
    <grant name="$name">
      <subject_name>$subject_name</subject_name>
      <validity><not_before>2020-01-01T00:00:00</not_before><not_after>2099-12-31T23:59:59</not_after></validity>
      <allow_rule>
        <domains><id_range><min>0</min></id_range></domains>
XML
    if ((${#publish[@]})); then
      printf '        <publish>\n          <topics>\n'; topics_xml "${publish[@]}"
      printf '          </topics>\n          <partitions><partition>*</partition></partitions>\n        </publish>\n'
    fi
    printf '        <subscribe>\n          <topics>\n'; topics_xml "${subscribe[@]}"
    printf '          </topics>\n          <partitions><partition>*</partition></partitions>\n        </subscribe>\n'
    cat <<XML
      </allow_rule>
      <default>DENY</default>
    </grant>
  </permissions>
</dds>
XML
  } >"$dir/permissions.xml"
  openssl smime -sign -in "$dir/permissions.xml" -text -out "$dir/permissions.p7s" \
    -signer "$ca/permissions_ca.pem" -inkey "$ca/permissions_ca_key.pem" 2>/dev/null
  cp "$ca/identity_ca.pem" "$dir/identity_ca.pem"
  cp "$ca/permissions_ca.pem" "$dir/permissions_ca.pem"
  cp "$ca/governance.p7s" "$dir/governance.p7s"
  echo "dds_security: $dir ($role, $subject_name)"
done
