"""What every benchmark needs, written once: clocks, stillness, teams, pose hygiene and sources."""
