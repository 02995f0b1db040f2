#!/bin/sh
# tests/schema/run.sh — api/scene.schema.json agrees with the daemon: schema.test.js validates
# every document of corpus.js with ajv (tests/browser/package.json's test tooling; `npm ci`
# there when it is missing) and POSTs it to an umbrad started here on loopback (ephemeral port).
# Ends with "N passed, N failed"; without node the suite says so and counts nothing. Env: BUILD.
BUILD=${BUILD:-build}
dir=$(dirname "$0")
. "$dir/../util/node_suite.sh"
node_tooling ajv ajv/dist/2020.js
node_start_umbrad "$T/port" "$T/umbrad.log" --workers 2 --no-playground
UMBRA_URL=$URL node "$dir/schema.test.js"
