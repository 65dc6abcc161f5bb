-- What a student saves mid-race: a syntax error.
return { update = function(self, car end }
