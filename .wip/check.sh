#!/bin/bash
cd /work/wt/h38p
cargo check --all-targets --keep-going --message-format=json > /tmp/h38p/c1.json 2>/tmp/h38p/c1.err
cargo check -p glossmeter-python --all-targets --keep-going --message-format=json > /tmp/h38p/c2.json 2>/tmp/h38p/c2.err
cargo check --lib --no-default-features --features serve --keep-going --message-format=json > /tmp/h38p/c3.json 2>/tmp/h38p/c3.err
