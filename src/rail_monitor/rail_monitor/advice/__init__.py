"""Speed advice across the models: per vehicle class, the speed bands that cut the peak corrugation
growth without raising the rolling noise by more than a limit or the share of squealing passes
(:mod:`.plan`), with the noise and squeal of each class at each speed (:mod:`.consequences`)."""
