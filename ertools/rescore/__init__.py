"""`ertools rescore`: a whole competition rescored, from folders of logs to one results site."""
