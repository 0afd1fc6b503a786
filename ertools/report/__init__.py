"""Reports: folders with HTML, YAML, JSON, CSV and figures. Only this layer draws."""
