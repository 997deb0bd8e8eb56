"""Speed advice across the models, in one place: the growth of a speed distribution and its grinding
interval (:mod:`.growth`), the linear programme of the advised bands (:mod:`.speed_plan`), the
noise and squeal of each class at each speed (:mod:`.consequences`), and per vehicle class the
bands that cut the peak corrugation growth without raising the rolling noise by more than a limit
or the share of squealing passes (:mod:`.plan`)."""
