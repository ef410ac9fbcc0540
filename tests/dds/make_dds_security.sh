#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Makes what DDS Security needs for a test cell (docs/MULTICAMERA.md, "Security"), with the
# openssl command only, into OUT_DIR:
#   ca.pem, ca.key                  one CA, both the identity CA and the permissions CA
#   <name>.pem, <name>.key          an identity certificate and key per participant NAME
#   governance.xml/.p7s             the domain's rules, signed by the CA
#   permissions.xml/.p7s            one grant per NAME, signed by the CA
#   rogue/...                       the same for a second, unrelated CA and one identity
#                                   "front": a participant every other one must refuse
# Keys are EC prime256v1 (Cyclone's PKI-DH takes RSA-2048 or P-256; P-256 is the faster to
# make). Certificates are valid for 2 days: test material, never a deployment's.
# Usage: make_dds_security.sh OUT_DIR NAME...
set -euo pipefail

if [[ $# -lt 2 ]]; then
  echo "usage: $0 OUT_DIR NAME..." >&2
  exit 2
fi
out=$1
shift
mkdir -p "$out/rogue"

# make_ca DIR CN: a self-signed CA key and certificate in DIR.
make_ca() {
  openssl genpkey -algorithm EC -pkeyopt ec_paramgen_curve:P-256 -out "$1/ca.key" 2>/dev/null
  openssl req -x509 -new -key "$1/ca.key" -subj "/C=DE/O=hrcsense test/CN=$2" -days 2 -out "$1/ca.pem"
}

# make_identity DIR NAME: NAME's key and certificate, signed by DIR's CA.
make_identity() {
  openssl genpkey -algorithm EC -pkeyopt ec_paramgen_curve:P-256 -out "$1/$2.key" 2>/dev/null
  openssl req -new -key "$1/$2.key" -subj "/C=DE/O=hrcsense test/CN=$2" |
    openssl x509 -req -CA "$1/ca.pem" -CAkey "$1/ca.key" -set_serial "$((RANDOM * 32768 + RANDOM))" -days 2 \
      -out "$1/$2.pem" 2>/dev/null
}

# The subject of NAME's certificate as the permissions document names it (RFC 2253).
subject_of() {
  openssl x509 -noout -subject -nameopt RFC2253 -in "$1/$2.pem" | sed 's/^subject=//'
}

# Governance: no unauthenticated participant is admitted, a participant's permissions are
# checked when it joins; a camera's measurements are encrypted and only a participant whose
# permissions allow the topic may read or write it; every other topic is signed.
write_governance() {
  cat >"$1/governance.xml" <<'EOF'
<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
     xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_governance.xsd">
  <domain_access_rules>
    <domain_rule>
      <domains><id_range><min>0</min><max>230</max></id_range></domains>
      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>
      <enable_join_access_control>true</enable_join_access_control>
      <discovery_protection_kind>ENCRYPT</discovery_protection_kind>
      <liveliness_protection_kind>SIGN</liveliness_protection_kind>
      <rtps_protection_kind>NONE</rtps_protection_kind>
      <topic_access_rules>
        <topic_rule>
          <topic_expression>*measurement*</topic_expression>
          <enable_discovery_protection>true</enable_discovery_protection>
          <enable_liveliness_protection>true</enable_liveliness_protection>
          <enable_read_access_control>true</enable_read_access_control>
          <enable_write_access_control>true</enable_write_access_control>
          <metadata_protection_kind>SIGN</metadata_protection_kind>
          <data_protection_kind>ENCRYPT</data_protection_kind>
        </topic_rule>
        <topic_rule>
          <topic_expression>*</topic_expression>
          <enable_discovery_protection>true</enable_discovery_protection>
          <enable_liveliness_protection>false</enable_liveliness_protection>
          <enable_read_access_control>true</enable_read_access_control>
          <enable_write_access_control>true</enable_write_access_control>
          <metadata_protection_kind>NONE</metadata_protection_kind>
          <data_protection_kind>SIGN</data_protection_kind>
        </topic_rule>
      </topic_access_rules>
    </domain_rule>
  </domain_access_rules>
</dds>
EOF
}

# One grant per NAME: a camera NAME may publish only its own measurement topic (and read
# anything); the participant "fuser" may publish and read anything.
write_permissions() {
  local dir=$1
  shift
  {
    echo '<?xml version="1.0" encoding="UTF-8"?>'
    echo '<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"'
    echo '     xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_permissions.xsd">'
    echo '  <permissions>'
    for name in "$@"; do
      local publish='*'
      [[ $name == fuser ]] || publish="rt/*/measurement/$name"
      cat <<EOF
    <grant name="$name">
      <subject_name>$(subject_of "$dir" "$name")</subject_name>
      <validity><not_before>2020-01-01T00:00:00</not_before><not_after>2100-01-01T00:00:00</not_after></validity>
      <allow_rule>
        <domains><id_range><min>0</min><max>230</max></id_range></domains>
        <publish><topics><topic>$publish</topic></topics><partitions><partition>*</partition></partitions></publish>
        <subscribe><topics><topic>*</topic></topics><partitions><partition>*</partition></partitions></subscribe>
      </allow_rule>
      <default>DENY</default>
    </grant>
EOF
    done
    echo '  </permissions>'
    echo '</dds>'
  } >"$dir/permissions.xml"
}

# sign DIR FILE: FILE.xml signed by DIR's CA as S/MIME (what Cyclone's access control reads).
sign() {
  openssl smime -sign -in "$1/$2.xml" -text -out "$1/$2.p7s" -signer "$1/ca.pem" -inkey "$1/ca.key"
}

for dir_cn in "$out:hrcsense test CA" "$out/rogue:rogue CA"; do
  dir=${dir_cn%%:*}
  make_ca "$dir" "${dir_cn#*:}"
  if [[ $dir == "$out" ]]; then names=("$@"); else names=(front); fi
  for name in "${names[@]}"; do make_identity "$dir" "$name"; done
  write_governance "$dir"
  write_permissions "$dir" "${names[@]}"
  sign "$dir" governance
  sign "$dir" permissions
done
